/*
 * testlib.h - the project's small test helper.
 *
 * CHECK(cond) and CHECK_NEAR(value, expected, relative) record a failure with file:line and
 * go on; test_finish() prints a summary and returns the process exit code. Helpers for CLI
 * tests run the tool, write scene files, and read outputs in a per-test scratch folder.
 */
#ifndef RAD_TESTLIB_H
#define RAD_TESTLIB_H

#include <stdbool.h>
#include <stdio.h>

#include "radiosity.h"

extern int test_failures;
extern int test_checks;

void test_fail(const char *file, int line, const char *format, ...)
    __attribute__((format(printf, 3, 4)));

#define CHECK(cond)                                                                        \
    do {                                                                                   \
        test_checks++;                                                                     \
        if (!(cond))                                                                       \
            test_fail(__FILE__, __LINE__, "CHECK(%s) failed", #cond);                      \
    } while (0)

/* |value - expected| <= relative * |expected| (or <= relative when expected is 0). */
#define CHECK_NEAR(value, expected, relative)                                              \
    do {                                                                                   \
        double v_ = (value), e_ = (expected), r_ = (relative);                             \
        test_checks++;                                                                     \
        double tol_ = e_ != 0 ? r_ * (e_ < 0 ? -e_ : e_) : r_;                             \
        double d_ = v_ - e_;                                                               \
        if (!(d_ <= tol_ && -d_ <= tol_))                                                  \
            test_fail(__FILE__, __LINE__, "%s = %.9g, expected %.9g within %.3g%s", #value, \
                      v_, e_, r_, e_ != 0 ? " relative" : "");                            \
    } while (0)

/* Absolute tolerance. */
#define CHECK_ABS(value, expected, tolerance)                                              \
    do {                                                                                   \
        double v_ = (value), e_ = (expected), t_ = (tolerance);                            \
        test_checks++;                                                                     \
        if (!(v_ - e_ <= t_ && e_ - v_ <= t_))                                             \
            test_fail(__FILE__, __LINE__, "%s = %.9g, expected %.9g within %.3g", #value,  \
                      v_, e_, t_);                                                         \
    } while (0)

/* The tests' own ray-triangle test (Moller-Trumbore, either side, double precision), an
 * oracle apart from the library's tracers: the distance t along d at which the ray from o
 * meets triangle (a, b, c), and the hit's barycentrics u (b's weight) and v (c's) when
 * not NULL; INFINITY when it misses or the ray runs in the triangle's plane. t may be 0 or
 * less: each caller keeps the hits past its own least distance. */
double test_ray_triangle(rad_vec3 o, rad_vec3 d, rad_vec3 a, rad_vec3 b, rad_vec3 c, double *u,
                         double *v);

/* Prints "name: N checks, M failed" and returns 0 when nothing failed. */
int test_finish(const char *name);

/* Creates (empty) the scratch folder RAD_TEST_TMP and returns its path. */
const char *test_tmpdir(void);

/* Path inside the scratch folder (static buffer rotated among 8). */
const char *test_path(const char *name);

/* Loads the scene file `name` of the scratch folder (rad_scene_load, no options); fails the
 * test (and returns NULL) when it cannot. */
rad_scene *test_load_scene(const char *name);

/* Writes text to a file in the scratch folder; returns its path. */
const char *test_write_file(const char *name, const char *text);

/* Runs the radiosity tool with the given argument string (shell syntax); stderr and stdout
 * are captured to test_path("stderr.txt") / ("stdout.txt"). Returns the exit code. */
int test_run_tool(const char *arguments);

/* Reads a whole small file into a static buffer ("" if missing). */
const char *test_read_text(const char *path);

/* The whole file, malloc'd (the caller frees it), its length in *size; NULL (and *size 0)
 * when it cannot be read. */
uint8_t *test_read_bytes(const char *path, size_t *size);
/* The vertex element's three float properties `names` of the binary PLY `name` in the
 * test folder, malloc'd as count x 3 floats; NULL when one is missing. */
float *test_ply_vertex_floats(const char *name, const char *const names[3], uint32_t *count);
/* The triangles of the binary PLY `name` (faces of 3 corners, "property list uchar int
 * vertex_indices", after the vertices), malloc'd as count x 3 vertex indices; NULL when the
 * file has another layout or a face that is not a triangle. */
uint32_t *test_ply_triangles(const char *name, uint32_t *count);

bool test_file_exists(const char *path);

/* True when both files can be read, are not empty and hold the same bytes. */
bool test_same_bytes(const char *a_path, const char *b_path);

/* A new black image (exits the test on failure), and pixel access. */
rad_image *test_new_image(uint32_t width, uint32_t height);
float *test_pixel(const rad_image *image, uint32_t x, uint32_t y);
void test_set_pixel(rad_image *image, uint32_t x, uint32_t y, double r, double g, double b);

/* Writes the furnace scene (VALIDATION.md section 3): a closed, inward-facing unit cube
 * whose six faces (objects zlo, zhi, xlo, xhi, ylo, yhi) all have Kd 0.5 and Ke 1, as
 * `name` with its material library furnace.mtl, in the scratch folder. */
void test_write_furnace(const char *name);

/* Counts the files in the scratch folder whose name starts with prefix. */
int test_count_files(const char *prefix);

/* rad_solve_hierarchical with the scene's patch inputs (rad_patch_inputs_build). */
/* The scene's uniform split at patch_size, with no shadow or proximity refinement: for
 * tests whose subject is not the mesh and whose expectations (patch, vertex and row
 * counts) are the uniform split's. */
rad_status test_mesh_uniform(const rad_scene *scene, double patch_size, rad_mesh **mesh,
                             rad_error *error);

rad_status test_solve_hierarchical(const rad_scene *scene, const rad_mesh *mesh,
                                   const rad_tracer *occluders,
                                   const rad_hierarchy_options *options, rad_rgb *B,
                                   rad_hierarchy_report *report, rad_error *error);

/* Writes an 8-bit RGB PNG (libpng) of width x height into the scratch folder; fails the
 * test when it cannot. */
void test_write_png(const char *name, uint32_t width, uint32_t height, const unsigned char *rgb);

/* The linear value of an 8-bit sRGB byte (IEC 61966-2-1), the reference for textures. */
double test_srgb_to_linear(unsigned byte);

/* A scene's OBJ text built in memory, for tests that write their own scenes: objects,
 * rectangles (and rectangles with a hole) in axis-aligned planes. */
typedef struct test_obj {
    char *data;
    size_t length, capacity;
    int vertices;
} test_obj;

void test_obj_add(test_obj *t, const char *format, ...) __attribute__((format(printf, 2, 3)));
/* "o NAME" and "usemtl MATERIAL" */
void test_obj_object(test_obj *t, const char *name, const char *material);
/* The rectangle in the plane coordinate[axis] = at, from (lo0, lo1) to (hi0, hi1) in the
 * next two axes (cyclically), facing +axis (facing > 0) or -axis. */
void test_obj_rectangle(test_obj *t, int axis, double at, double lo0, double lo1, double hi0,
                        double hi1, int facing);
/* The same with a rectangular hole, as four rectangles. */
void test_obj_rectangle_with_hole(test_obj *t, int axis, double at, double lo0, double lo1,
                                  double hi0, double hi1, double hole_lo0, double hole_lo1,
                                  double hole_hi0, double hole_hi1, int facing);
/* A box from (x0, y0, z0) to (x1, y1, z1) facing outwards, without its bottom (it stands
 * on a floor at y0) and, with `no_back`, without its -z face (it stands against a wall). */
void test_obj_box(test_obj *t, double x0, double y0, double z0, double x1, double y1,
                  double z1, bool no_back);

/* Per-surface means of an image's pixels: `surface[p]` classifies pixel p (row-major) as a
 * surface index in [0, TEST_MAX_SURFACES), or < 0 to leave it out. With `se` (an image of
 * per-pixel standard errors, the path tracer's) the standard error of each mean, the
 * pixels being independent samples. */
#define TEST_MAX_SURFACES 16

typedef struct test_surface_means {
    rad_rgb mean[TEST_MAX_SURFACES];
    rad_rgb se[TEST_MAX_SURFACES];
    uint32_t count[TEST_MAX_SURFACES];
} test_surface_means;

void test_image_surface_means(const rad_image *image, const rad_image *se, const int *surface,
                              test_surface_means *out);

/* Per-surface area-weighted means of B / pi over the surfaces' patches (count: patches). */
void test_solution_surface_means(const rad_scene *scene, const rad_mesh *mesh, const rad_rgb *B,
                                 test_surface_means *out);

#endif
