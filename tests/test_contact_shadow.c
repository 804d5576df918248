/*
 * test_contact_shadow.c - the images across a contact shadow and across a crease, against
 * independent references.
 *
 * Contact shadow: a black box stands on a grey floor (Kd 0.5) under a square emitter off
 * to one side; nothing else reflects, so the floor's radiance is exactly 0.5 / pi times
 * its direct irradiance from the emitter, which the test integrates itself: 128 x 128
 * points on the emitter, each segment tested against the box (a slab test; no tracer, no
 * mesh). The profile across the box's shadow (umbra at the box's foot, penumbra, open
 * floor) is read from the images, pixel by pixel. The issue asks for 2 % of the open
 * floor's value at every sample; what each renderer and solver meets today is held (see
 * the figures in test_contact).
 *
 * Crease: a grey floor meets a grey wall under the emitter. The radiance next to the edge
 * on either side comes from both surfaces' light (no closed form), so the reference is the
 * path tracer, run here: the pixels of each surface in bands 3.5 to 10 cm and 10 to 30 cm
 * from the edge, averaged along it, held within 1 % (plus three of the path tracer's
 * standard errors) on each side: a reconstruction that pulled values across the edge would
 * move the darker wall's band towards the floor's.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/vec3.h"
#include "render/camera.h"
#include "testlib.h"

#define SIZE 128
#define EMITTED 10.0 /* Ke: the emitter's radiance */
#define ALBEDO 0.5

/* ---- contact shadow ---------------------------------------------------------------- */

/* metres, y up: the floor y = 0, x and z in [-2, 2]; the box x, z in [-0.5, 0.5], y in
 * [0, 1]; the emitter x in [0.5, 1.5], z in [-0.5, 0.5] at y = 2.5, facing down */
#define CONTACT_CAMERA "--eye -1.2,6,0 --target -1.2,0,0 --up 0,0,-1 --fov 24 --size 128x128"

static void write_contact_scene(void)
{
    test_obj t = {0};
    test_obj_add(&t, "mtllib contact.mtl\n");
    test_obj_object(&t, "floor", "grey");
    test_obj_rectangle(&t, 1, 0, -2, -2, 2, 2, 1);
    test_obj_object(&t, "box", "black");
    test_obj_box(&t, -0.5, 0, -0.5, 0.5, 1, 0.5, false);
    test_obj_object(&t, "light", "light");
    test_obj_rectangle(&t, 1, 2.5, -0.5, 0.5, 0.5, 1.5, -1);
    test_write_file("contact.obj", t.data);
    free(t.data);
    test_write_file("contact.mtl", "newmtl grey\nKd 0.5 0.5 0.5\n"
                                   "newmtl black\nKd 0 0 0\n"
                                   "newmtl light\nKd 0 0 0\nKe 10 10 10\n");
}

/* Does the segment from p to q pass through the box's inside (a slab test)? */
static bool box_blocks(const double p[3], const double q[3])
{
    static const double lo[3] = {-0.5, 0, -0.5}, hi[3] = {0.5, 1, 0.5};
    double t0 = 1e-9, t1 = 1 - 1e-9;
    for (int a = 0; a < 3; a++) {
        double d = q[a] - p[a];
        if (fabs(d) < 1e-15) {
            if (p[a] <= lo[a] || p[a] >= hi[a])
                return false;
            continue;
        }
        double ta = (lo[a] - p[a]) / d, tb = (hi[a] - p[a]) / d;
        if (ta > tb) {
            double swap = ta;
            ta = tb;
            tb = swap;
        }
        t0 = fmax(t0, ta);
        t1 = fmin(t1, tb);
        if (t0 >= t1)
            return false;
    }
    return true;
}

/* The emitter's irradiance at floor point (x, 0, z): the midpoint rule on 128 x 128 cells
 * of the emitter, each cell's segment tested against the box. */
static double floor_irradiance(double x, double z)
{
    enum { N = 128 };
    double cell = 1.0 / N, sum = 0;
    for (int i = 0; i < N; i++)
        for (int k = 0; k < N; k++) {
            double e[3] = {0.5 + (i + 0.5) * cell, 2.5, -0.5 + (k + 0.5) * cell};
            double p[3] = {x, 0, z};
            if (box_blocks(p, e))
                continue;
            double dx = e[0] - x, dy = e[1], dz = e[2] - z;
            double r2 = dx * dx + dy * dy + dz * dz;
            sum += EMITTED * (dy * dy / r2) / r2 * cell * cell; /* cos at both ends: dy / r */
        }
    return sum;
}

static double luminance(const rad_image *image, uint32_t x, uint32_t y)
{
    const float *p = &image->rgb[3 * ((size_t)y * image->width + x)];
    return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
}

static rad_image *render(const char *command)
{
    rad_image *image = NULL;
    rad_error error;
    CHECK(test_run_tool(command) == 0);
    printf("%s\n  %s", command, test_read_text(test_path("stderr.txt")));
    CHECK(rad_image_read(test_path("image.pfm"), &image, &error) == RAD_OK);
    return image;
}

typedef struct profile {
    uint32_t count;
    uint32_t pixel_x[SIZE], pixel_y[SIZE];
    double x[SIZE];        /* the floor point's x (z within a pixel of 0) */
    double exact[SIZE];    /* 0.5 / pi x the irradiance there */
    double open;           /* the same on the open floor, x = -1.95 */
} profile;

/* The pixels whose centre sees the floor within 2 cm of z = 0, for x in [-1.95, -0.52]:
 * the box's shadow side, from its foot to the open floor. */
static void contact_profile(profile *out)
{
    memset(out, 0, sizeof(*out));
    rad_camera camera = {{-1.2, 6, 0}, {-1.2, 0, 0}, {0, 0, -1}, 24};
    camera_frame frame;
    rad_error error;
    CHECK(camera_frame_make(&camera, SIZE, SIZE, &frame, &error) == RAD_OK);
    for (uint32_t y = 0; y < SIZE; y++)
        for (uint32_t x = 0; x < SIZE; x++) {
            rad_vec3 d = camera_direction(&frame, x + 0.5, y + 0.5, SIZE, SIZE);
            double t = -frame.eye.y / d.y;
            double fx = frame.eye.x + t * d.x, fz = frame.eye.z + t * d.z;
            if (fabs(fz) > 0.02 || fx < -1.95 || fx > -0.52 || out->count == SIZE)
                continue;
            out->pixel_x[out->count] = x;
            out->pixel_y[out->count] = y;
            out->x[out->count] = fx;
            out->exact[out->count] = ALBEDO / RAD_PI * floor_irradiance(fx, fz);
            out->count++;
        }
    out->open = ALBEDO / RAD_PI * floor_irradiance(-1.95, 0);
}

/* Holds every profile pixel of `image` within `share` of the open floor's value (printing
 * the profile when asked); returns the largest difference as a share of the open value. */
static double check_profile(const profile *p, const rad_image *image, double share,
                            bool print)
{
    double worst = 0;
    for (uint32_t k = 0; k < p->count; k++) {
        double value = luminance(image, p->pixel_x[k], p->pixel_y[k]);
        double difference = (value - p->exact[k]) / p->open;
        if (print)
            printf("    x %+.3f m: %.5f, exact %.5f (%+.2f %% of open)\n", p->x[k], value,
                   p->exact[k], 100 * difference);
        CHECK_ABS(value, p->exact[k], share * p->open);
        worst = fmax(worst, fabs(difference));
    }
    return worst;
}

static void test_contact(void)
{
    profile p;
    contact_profile(&p);
    printf("contact shadow: %u pixels from x = -1.95 to -0.52 m, open floor %.5f\n", p.count,
           p.open);
    CHECK(p.count >= 40);
    /* the profile spans umbra (0 at the box's foot), penumbra and open floor */
    CHECK(p.exact[p.count - 1] < 0.05 * p.open || p.exact[0] < 0.05 * p.open);
    char command[1024];
    /* measured 2026-12-02, the largest difference as a share of the open floor's value
     * (the issue asks for 2 %): the default render (gather; the emitter's light computed at
     * the vertices and interpolated) 6.5 %, Gauss-Seidel and shooting the same, all at the
     * umbra's end (x = -1.17 m), where the light falls to zero inside a patch and the
     * interpolation between its vertices carries some 4 cm into the umbra (8.3 % with the
     * patch values interpolated instead); the hierarchical solver (30,000 patches) 1.0 %
     * (3.3 % with patch values); the per-pixel direct light 5.7 % at 16 samples a pixel
     * and 2.5 % at 256 (its noise: without bias; before the emitter samples were one
     * Halton point in all three dimensions it was 20 % at any sample count). Later the
     * same day the light at the vertices is shown on the mesh split where the emitters'
     * shadows bend the light (light_refine.h: 3667 -> 5341 patches for display): the
     * default 1.53 %, Gauss-Seidel and shooting the same, hierarchical 1.14 %; per pixel
     * (the emitters' unshadowed light exact, the shadow rays giving the share that gets
     * through) 6.5 % at 16 samples and 2.1 % at 256 */
    static const char *const runs[] = {"", "--solver gauss-seidel", "--solver shoot",
                                       "--solver hierarchical", "--direct pixel",
                                       "--direct pixel --spp 256"};
    static const double bounds[] = {0.02, 0.02, 0.02, 0.02, 0.07, 0.03};
    for (size_t r = 0; r < sizeof(runs) / sizeof(runs[0]); r++) {
        snprintf(command, sizeof(command), "render %s -o %s %s %s", test_path("contact.obj"),
                 test_path("image.pfm"), CONTACT_CAMERA, runs[r]);
        rad_image *image = render(command);
        if (!image)
            continue;
        double worst = check_profile(&p, image, bounds[r], r == 0);
        printf("  render %s: largest difference %.2f %% of the open floor (the issue asks for "
               "2 %%)\n",
               runs[r], 100 * worst);
        rad_image_destroy(image);
    }
    /* the path tracer sees the same scene through its own code: within its noise (measured
     * 5.6 % of the open floor at worst, 1024 samples a pixel) */
    snprintf(command, sizeof(command), "pathtrace %s -o %s %s --spp 1024",
             test_path("contact.obj"), test_path("image.pfm"), CONTACT_CAMERA);
    rad_image *traced = render(command);
    if (traced) {
        double worst = check_profile(&p, traced, 0.07, false);
        printf("  pathtrace 1024 spp: largest difference %.2f %% of the open floor\n",
               100 * worst);
        rad_image_destroy(traced);
    }
}

/* The lit mesh of the same scene (`solve -o`) as a viewer shows it: at points of a grid
 * over the floor (3 cm apart, off the patches' edges), the radiance interpolated over the
 * mesh triangle holding the point, against 0.5 / pi x the irradiance integrated there, as
 * a share of the open floor's value; the box's footprint and 2 cm around it (where the
 * light jumps between the box's face and the floor) are left out. Returns the largest
 * difference; prints where it is. */
static double lit_mesh_floor(const char *name, double open, uint32_t *checked, double *rms)
{
    static const char *const xyz[3] = {"x", "y", "z"};
    static const char *const radiance_names[3] = {"radiance_r", "radiance_g", "radiance_b"};
    uint32_t n = 0, nL = 0, triangle_count = 0;
    float *position = test_ply_vertex_floats(name, xyz, &n);
    float *L = test_ply_vertex_floats(name, radiance_names, &nL);
    uint32_t *triangles = test_ply_triangles(name, &triangle_count);
    CHECK(position != NULL && L != NULL && triangles != NULL && n == nL);
    /* the floor's triangles, binned by the cells of a 32 x 32 grid over it they touch */
    enum { BINS = 32 };
    uint32_t *bin_count = calloc(BINS * BINS, sizeof(*bin_count));
    uint32_t **bin = calloc(BINS * BINS, sizeof(*bin));
    for (uint32_t t = 0; position && triangles && t < triangle_count; t++) {
        const uint32_t *c = &triangles[3 * t];
        if (c[0] >= n || c[1] >= n || c[2] >= n)
            continue;
        double lo[2] = {HUGE_VAL, HUGE_VAL}, hi[2] = {-HUGE_VAL, -HUGE_VAL};
        bool on_floor = true;
        for (int k = 0; k < 3; k++) {
            const float *p = &position[3 * c[k]];
            on_floor = on_floor && fabs(p[1]) < 1e-6;
            lo[0] = fmin(lo[0], p[0]), hi[0] = fmax(hi[0], p[0]);
            lo[1] = fmin(lo[1], p[2]), hi[1] = fmax(hi[1], p[2]);
        }
        if (!on_floor)
            continue;
        int i0 = (int)floor((lo[0] + 2) / 4 * BINS), i1 = (int)floor((hi[0] + 2) / 4 * BINS);
        int j0 = (int)floor((lo[1] + 2) / 4 * BINS), j1 = (int)floor((hi[1] + 2) / 4 * BINS);
        for (int i = i0 < 0 ? 0 : i0; i <= i1 && i < BINS; i++)
            for (int j = j0 < 0 ? 0 : j0; j <= j1 && j < BINS; j++) {
                uint32_t **b = &bin[i * BINS + j];
                *b = realloc(*b, (bin_count[i * BINS + j] + 1) * sizeof(**b));
                (*b)[bin_count[i * BINS + j]++] = t;
            }
    }
    double worst = 0, where_x = 0, where_z = 0, squares = 0;
    uint32_t outside = 0; /* grid points in no floor triangle */
    *checked = 0;
    for (double x = -1.9037; x < 1.9; x += 0.03)
        for (double z = -1.9037; z < 1.9; z += 0.03) {
            if (fabs(x) < 0.52 && fabs(z) < 0.52)
                continue; /* under the box or beside its foot */
            int i = (int)floor((x + 2) / 4 * BINS), j = (int)floor((z + 2) / 4 * BINS);
            double shown = -1;
            for (uint32_t k = 0; k < bin_count[i * BINS + j] && shown < 0; k++) {
                const uint32_t *c = &triangles[3 * bin[i * BINS + j][k]];
                const float *a = &position[3 * c[0]], *b = &position[3 * c[1]],
                            *d = &position[3 * c[2]];
                double e1x = b[0] - a[0], e1z = b[2] - a[2], e2x = d[0] - a[0], e2z = d[2] - a[2];
                double det = e1x * e2z - e2x * e1z;
                if (det == 0)
                    continue;
                double u = ((x - a[0]) * e2z - e2x * (z - a[2])) / det;
                double v = (e1x * (z - a[2]) - (x - a[0]) * e1z) / det;
                if (u < -1e-9 || v < -1e-9 || u + v > 1 + 1e-9)
                    continue;
                shown = (1 - u - v) * L[3 * c[0] + 1] + u * L[3 * c[1] + 1] + v * L[3 * c[2] + 1];
            }
            if (shown < 0) {
                outside++;
                continue;
            }
            double exact = ALBEDO / RAD_PI * floor_irradiance(x, z);
            double difference = fabs(shown - exact) / open;
            if (difference > worst)
                worst = difference, where_x = x, where_z = z;
            squares += difference * difference;
            ++*checked;
        }
    CHECK(outside == 0); /* the floor is covered */
    *rms = *checked ? sqrt(squares / *checked) : HUGE_VAL;
    printf("  %s: %u floor points, RMS difference %.2f %% of the open floor, largest %.2f %% "
           "at x %+.3f, z %+.3f m\n",
           name, *checked, 100 * *rms, 100 * worst, where_x, where_z);
    for (int b = 0; b < BINS * BINS; b++)
        free(bin[b]);
    free(bin);
    free(bin_count);
    free(position);
    free(L);
    free(triangles);
    return worst;
}

/* The lit mesh takes its light where the image does: computed at the vertices by default
 * (the emitters' direct light there, plus a final gather), on the mesh split where the
 * emitters' shadows bend the light, so its floor follows the shadow, not the patch means
 * (--direct solution). Measured 2026-12-02 at the 14,973 grid points, as a share of the
 * open floor's value: the default lit mesh RMS 0.59 %, largest 10.1 % (x 0.47, z 0.68 m,
 * beside the box's corner on the emitter's side, in a steep penumbra); without the split
 * RMS 1.66 %, largest 101 % (x 0.50, z 0.53 m: a floor patch running from the box's foot
 * into its lit side); the patch means RMS 3.8 %, largest 111 % (x 0.53, z -0.04 m: next to
 * the box's lit face, under the emitter, where the floor is many times brighter than the
 * open floor at x = -1.95 m the shares are taken of). */
static void test_contact_lit_mesh(void)
{
    double open = ALBEDO / RAD_PI * floor_irradiance(-1.95, 0);
    char command[1024];
    uint32_t vertex_count = 0, patch_count = 0;
    double vertex_rms, patch_rms;
    snprintf(command, sizeof(command), "solve %s -o %s", test_path("contact.obj"),
             test_path("contact_vertex.ply"));
    CHECK(test_run_tool(command) == 0);
    double vertex = lit_mesh_floor("contact_vertex.ply", open, &vertex_count, &vertex_rms);
    snprintf(command, sizeof(command), "solve %s -o %s --direct solution",
             test_path("contact.obj"), test_path("contact_patches.ply"));
    CHECK(test_run_tool(command) == 0);
    double patches = lit_mesh_floor("contact_patches.ply", open, &patch_count, &patch_rms);
    CHECK(vertex_count >= 10000 && vertex_count == patch_count);
    CHECK(vertex_rms < 0.008 && vertex_rms < 0.3 * patch_rms);
    CHECK(vertex < 0.13 && vertex < 0.25 * patches);
}

/* ---- crease ------------------------------------------------------------------------ */

/* the floor y = 0, x in [0, 3]; the wall x = 0, y in [0, 3]; z in [-1.5, 1.5]; the
 * emitter x in [1, 2], z in [-0.5, 0.5] at y = 2.5, facing down */
#define CREASE_CAMERA "--eye 2,2,0 --target 0,0,0 --up 0,1,0 --fov 60 --size 128x128"
#define BANDS 2

static const double band_edge[BANDS + 1] = {0.035, 0.10, 0.30};

static void write_crease_scene(void)
{
    test_obj t = {0};
    test_obj_add(&t, "mtllib crease.mtl\n");
    test_obj_object(&t, "floor", "grey");
    test_obj_rectangle(&t, 1, 0, -1.5, 0, 1.5, 3, 1);
    test_obj_object(&t, "wall", "grey");
    test_obj_rectangle(&t, 0, 0, 0, -1.5, 3, 1.5, 1);
    test_obj_object(&t, "light", "light");
    test_obj_rectangle(&t, 1, 2.5, -0.5, 1, 0.5, 2, -1);
    test_write_file("crease.obj", t.data);
    free(t.data);
    test_write_file("crease.mtl", "newmtl grey\nKd 0.5 0.5 0.5\n"
                                  "newmtl light\nKd 0 0 0\nKe 10 10 10\n");
}

/* Per pixel: its band (side * BANDS + band; -1 for none) by where its centre's ray meets
 * the floor (side 0) or the wall (side 1), |z| < 1. */
static void crease_bands(int *band)
{
    rad_camera camera = {{2, 2, 0}, {0, 0, 0}, {0, 1, 0}, 60};
    camera_frame frame;
    rad_error error;
    CHECK(camera_frame_make(&camera, SIZE, SIZE, &frame, &error) == RAD_OK);
    for (uint32_t y = 0; y < SIZE; y++)
        for (uint32_t x = 0; x < SIZE; x++) {
            rad_vec3 d = camera_direction(&frame, x + 0.5, y + 0.5, SIZE, SIZE);
            double t_floor = d.y < 0 ? -frame.eye.y / d.y : INFINITY;
            double t_wall = d.x < 0 ? -frame.eye.x / d.x : INFINITY;
            int side = t_floor < t_wall ? 0 : 1;
            double t = fmin(t_floor, t_wall);
            rad_vec3 hit = v3(frame.eye.x + t * d.x, frame.eye.y + t * d.y, frame.eye.z + t * d.z);
            double distance = side == 0 ? hit.x : hit.y;
            band[y * SIZE + x] = -1;
            if (!isfinite(t) || fabs(hit.z) > 1)
                continue;
            for (int b = 0; b < BANDS; b++)
                if (distance >= band_edge[b] && distance < band_edge[b + 1])
                    band[y * SIZE + x] = side * BANDS + b;
        }
}

static void band_means(const rad_image *image, const rad_image *se, const int *band,
                       double *mean, double *error, uint32_t *count)
{
    double sum[2 * BANDS] = {0}, variance[2 * BANDS] = {0};
    for (int b = 0; b < 2 * BANDS; b++)
        count[b] = 0;
    for (uint32_t p = 0; p < SIZE * SIZE; p++) {
        int b = band[p];
        if (b < 0)
            continue;
        sum[b] += luminance(image, p % SIZE, p / SIZE);
        if (se) {
            double s = luminance(se, p % SIZE, p / SIZE);
            variance[b] += s * s;
        }
        count[b]++;
    }
    for (int b = 0; b < 2 * BANDS; b++) {
        mean[b] = count[b] ? sum[b] / count[b] : 0;
        error[b] = count[b] ? sqrt(variance[b]) / count[b] : 0;
    }
}

static void test_crease(void)
{
    write_crease_scene();
    int *band = malloc(SIZE * SIZE * sizeof(int));
    if (!band)
        exit(1);
    crease_bands(band);
    char command[1024];
    snprintf(command, sizeof(command), "pathtrace %s -o %s %s --spp 1024 --standard-error %s",
             test_path("crease.obj"), test_path("image.pfm"), CREASE_CAMERA,
             test_path("se.pfm"));
    rad_image *traced = render(command), *se = NULL;
    rad_error error;
    CHECK(rad_image_read(test_path("se.pfm"), &se, &error) == RAD_OK);
    if (!traced || !se) {
        free(band);
        return;
    }
    double reference[2 * BANDS], reference_se[2 * BANDS];
    uint32_t count[2 * BANDS];
    band_means(traced, se, band, reference, reference_se, count);
    static const char *const side_name[2] = {"floor", "wall"};
    static const char *const runs[] = {"", "--direct pixel", "--solver hierarchical"};
    for (size_t r = 0; r < sizeof(runs) / sizeof(runs[0]); r++) {
        snprintf(command, sizeof(command), "render %s -o %s %s %s", test_path("crease.obj"),
                 test_path("image.pfm"), CREASE_CAMERA, runs[r]);
        rad_image *image = render(command);
        if (!image)
            continue;
        double mean[2 * BANDS], unused[2 * BANDS];
        uint32_t n[2 * BANDS];
        band_means(image, NULL, band, mean, unused, n);
        for (int b = 0; b < 2 * BANDS; b++) {
            CHECK(count[b] >= 100);
            printf("    %-5s %4.1f-%4.1f cm (%4u pixels): %.5f, path tracer %.5f +- %.5f "
                   "(%+.2f %%)\n",
                   side_name[b / BANDS], 100 * band_edge[b % BANDS],
                   100 * band_edge[b % BANDS + 1], n[b], mean[b], reference[b],
                   reference_se[b], 100 * (mean[b] - reference[b]) / reference[b]);
            CHECK_ABS(mean[b], reference[b], 0.01 * reference[b] + 3 * reference_se[b]);
        }
        rad_image_destroy(image);
    }
    /* the two sides differ (else nothing could be pulled across) */
    CHECK(reference[BANDS] < 0.8 * reference[0] || reference[0] < 0.8 * reference[BANDS]);
    rad_image_destroy(traced);
    rad_image_destroy(se);
    free(band);
}

int main(void)
{
    write_contact_scene();
    test_contact_lit_mesh();
    test_contact();
    test_crease();
    return test_finish("test_contact_shadow");
}
