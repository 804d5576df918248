/*
 * testlib.c - see testlib.h.
 */
#include "testlib.h"

#include <dirent.h>
#include <math.h>
#include <png.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

int test_failures;
int test_checks;

void test_fail(const char *file, int line, const char *format, ...)
{
    va_list args;
    va_start(args, format);
    fprintf(stderr, "%s:%d: ", file, line);
    vfprintf(stderr, format, args);
    fputc('\n', stderr);
    va_end(args);
    test_failures++;
}

int test_finish(const char *name)
{
    printf("%s: %d checks, %d failed\n", name, test_checks, test_failures);
    return test_failures == 0 && test_checks > 0 ? 0 : 1;
}

const char *test_tmpdir(void)
{
    static bool made;
    if (!made) {
        char command[4200];
        snprintf(command, sizeof(command), "rm -rf '%s' && mkdir -p '%s'", RAD_TEST_TMP,
                 RAD_TEST_TMP);
        if (system(command) != 0) {
            fprintf(stderr, "cannot create %s\n", RAD_TEST_TMP);
            exit(1);
        }
        made = true;
    }
    return RAD_TEST_TMP;
}

const char *test_path(const char *name)
{
    static char buffers[8][4200];
    static int next;
    char *buffer = buffers[next++ % 8];
    snprintf(buffer, sizeof(buffers[0]), "%s/%s", test_tmpdir(), name);
    return buffer;
}

rad_scene *test_load_scene(const char *name)
{
    rad_scene *scene = NULL;
    rad_error error;
    if (rad_scene_load(test_path(name), NULL, &scene, &error) != RAD_OK)
        test_fail(__FILE__, __LINE__, "%s: %s", name, error.message);
    return scene;
}

const char *test_write_file(const char *name, const char *text)
{
    const char *path = test_path(name);
    FILE *f = fopen(path, "wb");
    if (!f || fputs(text, f) < 0 || fclose(f) != 0) {
        fprintf(stderr, "cannot write %s\n", path);
        exit(1);
    }
    return path;
}

int test_run_tool(const char *arguments)
{
    char command[16384];
    char out[4200], err[4200];
    snprintf(out, sizeof(out), "%s", test_path("stdout.txt"));
    snprintf(err, sizeof(err), "%s", test_path("stderr.txt"));
    snprintf(command, sizeof(command), "cd '%s' && '%s' %s >'%s' 2>'%s' </dev/null",
             test_tmpdir(), RAD_TOOL, arguments, out, err);
    int status = system(command);
    if (status == -1 || !WIFEXITED(status))
        return -1;
    return WEXITSTATUS(status);
}

const char *test_read_text(const char *path)
{
    static char buffer[1 << 20];
    buffer[0] = 0;
    FILE *f = fopen(path, "rb");
    if (!f)
        return buffer;
    size_t n = fread(buffer, 1, sizeof(buffer) - 1, f);
    buffer[n] = 0;
    fclose(f);
    return buffer;
}

uint8_t *test_read_bytes(const char *path, size_t *size)
{
    *size = 0;
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    uint8_t *bytes = NULL;
    long length = -1;
    if (fseek(f, 0, SEEK_END) == 0)
        length = ftell(f);
    if (length >= 0 && fseek(f, 0, SEEK_SET) == 0 &&
        (bytes = malloc(length > 0 ? (size_t)length : 1)) != NULL)
        *size = fread(bytes, 1, (size_t)length, f);
    fclose(f);
    return bytes;
}

bool test_file_exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

int test_count_files(const char *prefix)
{
    DIR *dir = opendir(test_tmpdir());
    int count = 0;
    if (!dir)
        return 0;
    for (struct dirent *entry; (entry = readdir(dir));)
        if (strncmp(entry->d_name, prefix, strlen(prefix)) == 0)
            count++;
    closedir(dir);
    return count;
}

void test_write_furnace(const char *name)
{
    test_write_file(name, "mtllib furnace.mtl\n"
                          "usemtl glow\n"
                          "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
                          "o zlo\nf 1 2 3 4\n"
                          "o zhi\nf 5 8 7 6\n"
                          "o xlo\nf 1 4 8 5\n"
                          "o xhi\nf 2 6 7 3\n"
                          "o ylo\nf 1 5 6 2\n"
                          "o yhi\nf 4 3 7 8\n");
    test_write_file("furnace.mtl", "newmtl glow\nKd 0.5 0.5 0.5\nKe 1 1 1\n");
}

rad_image *test_new_image(uint32_t width, uint32_t height)
{
    rad_image *image = NULL;
    rad_error error;
    if (rad_image_create(width, height, &image, &error) != RAD_OK) {
        fprintf(stderr, "rad_image_create: %s\n", error.message);
        exit(1);
    }
    return image;
}

float *test_pixel(const rad_image *image, uint32_t x, uint32_t y)
{
    return image->rgb + ((size_t)y * image->width + x) * 3;
}

void test_set_pixel(rad_image *image, uint32_t x, uint32_t y, double r, double g, double b)
{
    float *p = test_pixel(image, x, y);
    p[0] = (float)r;
    p[1] = (float)g;
    p[2] = (float)b;
}

rad_status test_solve_hierarchical(const rad_scene *scene, const rad_mesh *mesh,
                                   const rad_tracer *occluders,
                                   const rad_hierarchy_options *options, rad_rgb *B,
                                   rad_hierarchy_report *report, rad_error *error)
{
    rad_patch_inputs *inputs = NULL;
    rad_status status = rad_patch_inputs_build(scene, mesh, &inputs, error);
    if (status == RAD_OK)
        status = rad_solve_hierarchical(mesh, inputs, occluders, options, B, report, error);
    rad_patch_inputs_destroy(inputs);
    return status;
}

void test_write_png(const char *name, uint32_t width, uint32_t height, const unsigned char *rgb)
{
    png_image image;
    memset(&image, 0, sizeof(image));
    image.version = PNG_IMAGE_VERSION;
    image.width = width;
    image.height = height;
    image.format = PNG_FORMAT_RGB;
    if (!png_image_write_to_file(&image, test_path(name), 0, rgb, 0, NULL))
        test_fail(__FILE__, __LINE__, "cannot write %s", name);
}

double test_srgb_to_linear(unsigned byte)
{
    double c = byte / 255.0;
    return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4);
}

void test_image_surface_means(const rad_image *image, const rad_image *se, const int *surface,
                              test_surface_means *out)
{
    double var[TEST_MAX_SURFACES][3] = {{0}};
    memset(out, 0, sizeof(*out));
    size_t pixels = (size_t)image->width * image->height;
    for (size_t p = 0; p < pixels; p++) {
        int s = surface[p];
        if (s < 0 || s >= TEST_MAX_SURFACES)
            continue;
        const float *v = &image->rgb[p * 3];
        out->mean[s].r += v[0];
        out->mean[s].g += v[1];
        out->mean[s].b += v[2];
        out->count[s]++;
        if (se)
            for (int c = 0; c < 3; c++)
                var[s][c] += (double)se->rgb[p * 3 + c] * se->rgb[p * 3 + c];
    }
    for (int s = 0; s < TEST_MAX_SURFACES; s++)
        if (out->count[s]) {
            double n = out->count[s];
            out->mean[s] = (rad_rgb){out->mean[s].r / n, out->mean[s].g / n, out->mean[s].b / n};
            out->se[s] = (rad_rgb){sqrt(var[s][0]) / n, sqrt(var[s][1]) / n, sqrt(var[s][2]) / n};
        }
}

void test_solution_surface_means(const rad_scene *scene, const rad_mesh *mesh, const rad_rgb *B,
                                 test_surface_means *out)
{
    double area[TEST_MAX_SURFACES] = {0};
    memset(out, 0, sizeof(*out));
    for (uint32_t i = 0; i < mesh->patch_count; i++) {
        const rad_patch *p = &mesh->patches[i];
        if (p->surface >= TEST_MAX_SURFACES || p->surface >= scene->surface_count)
            continue;
        area[p->surface] += p->area;
        out->mean[p->surface].r += p->area * B[i].r / 3.14159265358979323846;
        out->mean[p->surface].g += p->area * B[i].g / 3.14159265358979323846;
        out->mean[p->surface].b += p->area * B[i].b / 3.14159265358979323846;
        out->count[p->surface]++;
    }
    for (uint32_t s = 0; s < scene->surface_count && s < TEST_MAX_SURFACES; s++)
        if (area[s] > 0)
            out->mean[s] = (rad_rgb){out->mean[s].r / area[s], out->mean[s].g / area[s],
                                     out->mean[s].b / area[s]};
}

bool test_same_bytes(const char *a_path, const char *b_path)
{
    size_t a_size, b_size;
    uint8_t *a = test_read_bytes(a_path, &a_size), *b = test_read_bytes(b_path, &b_size);
    bool same = a && b && a_size == b_size && a_size > 0 && memcmp(a, b, a_size) == 0;
    free(a);
    free(b);
    return same;
}

rad_status test_mesh_uniform(const rad_scene *scene, double patch_size, rad_mesh **mesh,
                             rad_error *error)
{
    rad_mesh_options options = {.patch_size = patch_size, .shadow_levels = -1};
    return rad_mesh_build_with(scene, &options, mesh, error);
}

void test_obj_add(test_obj *t, const char *format, ...)
{
    va_list args;
    va_start(args, format);
    int n = vsnprintf(NULL, 0, format, args);
    va_end(args);
    if (t->length + (size_t)n + 1 > t->capacity) {
        t->capacity = 2 * (t->length + (size_t)n + 1);
        t->data = realloc(t->data, t->capacity);
        if (!t->data)
            abort();
    }
    va_start(args, format);
    vsnprintf(t->data + t->length, (size_t)n + 1, format, args);
    va_end(args);
    t->length += (size_t)n;
}

void test_obj_object(test_obj *t, const char *name, const char *material)
{
    test_obj_add(t, "o %s\nusemtl %s\n", name, material);
}

void test_obj_rectangle(test_obj *t, int axis, double at, double lo0, double lo1, double hi0,
                        double hi1, int facing)
{
    double corner[4][2] = {{lo0, lo1}, {hi0, lo1}, {hi0, hi1}, {lo0, hi1}};
    for (int k = 0; k < 4; k++) {
        const double *c = corner[facing > 0 ? k : 3 - k];
        double p[3];
        p[axis] = at;
        p[(axis + 1) % 3] = c[0];
        p[(axis + 2) % 3] = c[1];
        test_obj_add(t, "v %.6g %.6g %.6g\n", p[0], p[1], p[2]);
    }
    int v = t->vertices;
    test_obj_add(t, "f %d %d %d %d\n", v + 1, v + 2, v + 3, v + 4);
    t->vertices += 4;
}

void test_obj_rectangle_with_hole(test_obj *t, int axis, double at, double lo0, double lo1,
                                  double hi0, double hi1, double hole_lo0, double hole_lo1,
                                  double hole_hi0, double hole_hi1, int facing)
{
    test_obj_rectangle(t, axis, at, lo0, lo1, hole_lo0, hi1, facing);
    test_obj_rectangle(t, axis, at, hole_hi0, lo1, hi0, hi1, facing);
    test_obj_rectangle(t, axis, at, hole_lo0, lo1, hole_hi0, hole_lo1, facing);
    test_obj_rectangle(t, axis, at, hole_lo0, hole_hi1, hole_hi0, hi1, facing);
}

void test_obj_box(test_obj *t, double x0, double y0, double z0, double x1, double y1,
                  double z1, bool no_back)
{
    test_obj_rectangle(t, 0, x0, y0, z0, y1, z1, -1);
    test_obj_rectangle(t, 0, x1, y0, z0, y1, z1, 1);
    test_obj_rectangle(t, 1, y1, z0, x0, z1, x1, 1);
    if (!no_back)
        test_obj_rectangle(t, 2, z0, x0, y0, x1, y1, -1);
    test_obj_rectangle(t, 2, z1, x0, y0, x1, y1, 1);
}

/* A little-endian float. */
static float little_f32(const uint8_t *p)
{
    uint32_t bits = (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 |
                    (uint32_t)p[3] << 24;
    float v;
    memcpy(&v, &bits, sizeof(v));
    return v;
}

/* The vertex element's three float properties `names` of a binary PLY (any property
 * order, float/uchar/int types) of the file `name` in the test folder, malloc'd as
 * count x 3 floats; NULL when one is missing. */
/* Where a binary PLY's parts are: the vertex records after `header` bytes, `record` bytes
 * each, the float properties `names` (NULL: not wanted) at offset[k] in a record
 * (SIZE_MAX: missing), then `faces` faces, whose list is "uchar int vertex_indices" when
 * `int_lists`. False when the header has no end. */
typedef struct ply_layout {
    size_t header, record, offset[3];
    uint32_t vertices, faces;
    bool int_lists;
} ply_layout;

static bool ply_layout_of(const uint8_t *bytes, const char *const names[3], ply_layout *out)
{
    const char *end = bytes ? strstr((const char *)bytes, "end_header\n") : NULL;
    if (!end)
        return false;
    *out = (ply_layout){(size_t)(end - (const char *)bytes) + strlen("end_header\n"), 0,
                        {SIZE_MAX, SIZE_MAX, SIZE_MAX}, 0, 0, false};
    bool in_vertex = false;
    for (const char *line = (const char *)bytes; line < end;) {
        const char *next = strchr(line, '\n');
        char text[128] = {0}, type[32], property[64];
        memcpy(text, line, (size_t)(next - line) < sizeof(text) - 1 ? (size_t)(next - line)
                                                                    : sizeof(text) - 1);
        unsigned u;
        if (sscanf(text, "element vertex %u", &u) == 1) {
            in_vertex = true;
            out->vertices = u;
        } else if (sscanf(text, "element face %u", &u) == 1) {
            in_vertex = false;
            out->faces = u;
        } else if (strncmp(text, "element ", 8) == 0) {
            in_vertex = false;
        } else if (strcmp(text, "property list uchar int vertex_indices") == 0) {
            out->int_lists = true;
        } else if (in_vertex && sscanf(text, "property %31s %63s", type, property) == 2) {
            for (int k = 0; names && k < 3; k++)
                if (strcmp(property, names[k]) == 0 && strcmp(type, "float") == 0)
                    out->offset[k] = out->record;
            out->record += strcmp(type, "uchar") == 0 ? 1 : 4;
        }
        line = next + 1;
    }
    return true;
}

float *test_ply_vertex_floats(const char *name, const char *const names[3], uint32_t *count)
{
    *count = 0;
    size_t size = 0;
    uint8_t *bytes = test_read_bytes(test_path(name), &size);
    ply_layout ply;
    float *values = NULL;
    if (ply_layout_of(bytes, names, &ply) && ply.offset[0] != SIZE_MAX &&
        ply.offset[1] != SIZE_MAX && ply.offset[2] != SIZE_MAX &&
        ply.header + (size_t)ply.vertices * ply.record <= size) {
        values = calloc(3 * (size_t)ply.vertices + 1, sizeof(*values));
        for (uint32_t v = 0; values && v < ply.vertices; v++)
            for (int k = 0; k < 3; k++)
                values[3 * v + k] = little_f32(bytes + ply.header + v * ply.record + ply.offset[k]);
        *count = values ? ply.vertices : 0;
    }
    free(bytes);
    return values;
}

uint32_t *test_ply_triangles(const char *name, uint32_t *count)
{
    *count = 0;
    size_t size = 0;
    uint8_t *bytes = test_read_bytes(test_path(name), &size);
    ply_layout ply;
    uint32_t *triangles = NULL;
    if (ply_layout_of(bytes, NULL, &ply) && ply.int_lists &&
        ply.header + (size_t)ply.vertices * ply.record + (size_t)ply.faces * 13 <= size) {
        const uint8_t *face = bytes + ply.header + (size_t)ply.vertices * ply.record;
        triangles = calloc(3 * (size_t)ply.faces + 1, sizeof(*triangles));
        for (uint32_t f = 0; triangles && f < ply.faces; f++, face += 13) {
            if (face[0] != 3) {
                free(triangles);
                triangles = NULL;
                break;
            }
            for (int k = 0; k < 3; k++) {
                const uint8_t *q = face + 1 + 4 * k;
                triangles[3 * f + k] = (uint32_t)q[0] | (uint32_t)q[1] << 8 |
                                       (uint32_t)q[2] << 16 | (uint32_t)q[3] << 24;
            }
        }
        *count = triangles ? ply.faces : 0;
    }
    free(bytes);
    return triangles;
}

static rad_vec3 minus(rad_vec3 a, rad_vec3 b) { return (rad_vec3){a.x - b.x, a.y - b.y, a.z - b.z}; }
static double inner(rad_vec3 a, rad_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static rad_vec3 outer(rad_vec3 a, rad_vec3 b)
{
    return (rad_vec3){a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

double test_ray_triangle(rad_vec3 o, rad_vec3 d, rad_vec3 a, rad_vec3 b, rad_vec3 c, double *u,
                         double *v)
{
    rad_vec3 e1 = minus(b, a), e2 = minus(c, a), p = outer(d, e2);
    double det = inner(e1, p);
    if (!(fabs(det) > 1e-300))
        return INFINITY;
    rad_vec3 s = minus(o, a), q = outer(s, e1);
    double bu = inner(s, p) / det, bv = inner(d, q) / det;
    if (!(bu >= 0 && bv >= 0 && bu + bv <= 1))
        return INFINITY;
    if (u)
        *u = bu;
    if (v)
        *v = bv;
    return inner(e2, q) / det;
}
