/*
 * test_ply_input.c - the project's PLY reader (src/scene/import_ply.c), through
 * rad_scene_load.
 *
 * Refusals, each with its exact message: a row count or a list length beyond 64 bits
 * (refused as such, not as a file "holding" 2^64 - 1 rows), a list length of a floating
 * type, face vertex indices outside the vertex list, in ASCII and in binary (Assimp 5.2
 * kept an index's low 32 bits: 4294967296 would have been vertex 0 without a word),
 * coordinates that are not finite numbers, rows after the last one declared.
 *
 * Loads, against hand-computed areas and triangle counts: a square quad of area 2 (2
 * triangles) and a convex pentagon of area 7 by the shoelace formula (3 triangles) in
 * binary big- and little-endian files with mixed types (double and float coordinates, an
 * ignored uchar colour, uchar and ushort list counts, int and uint indices, an edge
 * element with a list before the faces and another element after them) and in ASCII with
 * comments, obj_info lines and CRLF line endings; PLY content under another extension;
 * the surface named after the file; the material element's first row (uchar colours over
 * 255) and the default albedo without one.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "testlib.h"

static void expect_refused(const char *name, const char *text, size_t length,
                           const char *message)
{
    FILE *file = fopen(test_path(name), "wb");
    if (file) {
        fwrite(text, 1, length, file);
        fclose(file);
    }
    rad_scene *scene = NULL;
    rad_error error = {0};
    rad_status status = rad_scene_load(test_path(name), NULL, &scene, &error);
    char expected[1024];
    snprintf(expected, sizeof(expected), "%s%s", test_path(name), message);
    if (status != RAD_ERR_PARSE || scene || strcmp(error.message, expected) != 0)
        test_fail(__FILE__, __LINE__, "%s: expected '%s', got '%s'", name, expected,
                  scene ? "(loaded)" : error.message);
    rad_scene_destroy(scene);
}

#define HEADER(format, vertices, count_type, index_type)                                   \
    "ply\nformat " format " 1.0\nelement vertex " vertices "\nproperty float x\n"             \
    "property float y\nproperty float z\nelement face 1\nproperty list " count_type " "     \
    index_type " vertex_indices\nend_header\n"
#define ASCII_HEADER HEADER("ascii", "3", "uchar", "int")
#define VERTICES "0 0 0\n1 0 0\n0 1 0\n"

static void ascii(const char *name, const char *text, const char *message)
{
    expect_refused(name, text, strlen(text), message);
}


/* ---- binary files built value by value, in either byte order */

typedef struct bytes {
    unsigned char data[4096];
    size_t length;
    bool big;
} bytes;

static void put(bytes *b, const void *value, size_t size)
{
    for (size_t k = 0; k < size && b->length < sizeof(b->data); k++) {
        /* the machine is little-endian: byte k of the value, or its mirror */
        size_t from = b->big ? size - 1 - k : k;
        b->data[b->length++] = ((const unsigned char *)value)[from];
    }
}

static void put_text(bytes *b, const char *text)
{
    size_t n = strlen(text);
    if (b->length + n <= sizeof(b->data)) {
        memcpy(b->data + b->length, text, n);
        b->length += n;
    }
}

static void put_u8(bytes *b, uint8_t v) { put(b, &v, 1); }
static void put_u16(bytes *b, uint16_t v) { put(b, &v, 2); }
static void put_i32(bytes *b, int32_t v) { put(b, &v, 4); }
static void put_u32(bytes *b, uint32_t v) { put(b, &v, 4); }
static void put_f32(bytes *b, float v) { put(b, &v, 4); }
static void put_f64(bytes *b, double v) { put(b, &v, 8); }

/* The quad (area 2, z = 0) and the convex pentagon (area 7 by the shoelace formula:
 * (0 + 2 + 8 + 4 + 0) / 2, z = 1), 9 vertices. */
static const double shape_corners[9][3] = {{0, 0, 0}, {2, 0, 0}, {2, 1, 0}, {0, 1, 0},
                                     {0, 0, 1}, {2, 0, 1}, {3, 1, 1}, {1, 3, 1}, {-1, 1, 1}};
#define TOTAL_AREA 9.0

static rad_scene *load(const char *path)
{
    rad_scene *scene = NULL;
    rad_error error = {0};
    if (rad_scene_load(path, NULL, &scene, &error) != RAD_OK)
        test_fail(__FILE__, __LINE__, "%s: %s", path, error.message);
    return scene;
}

/* The loaded quad and pentagon: 5 triangles, area 9, one surface named `surface`, the
 * material's albedo `albedo`. */
static void expect_shapes(const char *what, rad_scene *scene, const char *surface, double albedo)
{
    CHECK(scene != NULL);
    if (!scene)
        return;
    printf("%s: %u triangles, area %.17g, surface '%s', albedo %g\n", what,
           scene->triangle_count, rad_scene_area(scene), scene->surfaces[0].name,
           scene->materials[0].albedo.r);
    CHECK(scene->triangle_count == 5);
    CHECK_NEAR(rad_scene_area(scene), TOTAL_AREA, 1e-12);
    CHECK(scene->surface_count == 1 && strcmp(scene->surfaces[0].name, surface) == 0);
    CHECK(scene->material_count == 1);
    CHECK_NEAR(scene->materials[0].albedo.r, albedo, 1e-12);
    /* the pentagon's three triangles: 7 of the area at z = 1 */
    double upper = 0;
    for (uint32_t t = 0; t < scene->triangle_count; t++) {
        rad_vec3 a = scene->positions[scene->triangles[t].vertex[0]];
        rad_vec3 b = scene->positions[scene->triangles[t].vertex[1]];
        rad_vec3 c = scene->positions[scene->triangles[t].vertex[2]];
        double cross = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
        CHECK(cross > 0); /* counter-clockwise, as written */
        if (a.z == 1 && b.z == 1 && c.z == 1)
            upper += cross / 2;
    }
    CHECK_NEAR(upper, 7.0, 1e-12);
}

/* A binary file of both shapes: double x, float y, double z, an ignored uchar colour; an
 * edge element (with a list of floats) before the faces, a "note" element after them;
 * list counts `count16` ? ushort : uchar, indices `unsigned_indices` ? uint : int. */
static void binary_shapes(bool big, bool count16, bool unsigned_indices)
{
    bytes b = {.big = big};
    char header[1024];
    snprintf(header, sizeof(header),
             "ply\nformat %s 1.0\ncomment mixed types\nelement vertex 9\nproperty double x\n"
             "property float32 y\nproperty float64 z\nproperty uchar red\nelement edge 2\n"
             "property int vertex1\nproperty list uint8 float weights\nelement face 2\n"
             "property list %s %s vertex_indices\nproperty short flags\nelement note 1\n"
             "property list uchar uchar text\nproperty double value\nend_header\n",
             big ? "binary_big_endian" : "binary_little_endian", count16 ? "ushort" : "uchar",
             unsigned_indices ? "uint" : "int");
    put_text(&b, header);
    for (int v = 0; v < 9; v++) {
        put_f64(&b, shape_corners[v][0]);
        put_f32(&b, (float)shape_corners[v][1]);
        put_f64(&b, shape_corners[v][2]);
        put_u8(&b, 200);
    }
    for (int e = 0; e < 2; e++) { /* edge: vertex1, then 3 weights */
        put_i32(&b, e);
        put_u8(&b, 3);
        for (int k = 0; k < 3; k++)
            put_f32(&b, 0.5f);
    }
    for (int f = 0; f < 2; f++) {
        int n = f ? 5 : 4, first = f ? 4 : 0;
        if (count16)
            put_u16(&b, (uint16_t)n);
        else
            put_u8(&b, (uint8_t)n);
        for (int k = 0; k < n; k++) {
            if (unsigned_indices)
                put_u32(&b, (uint32_t)(first + k));
            else
                put_i32(&b, first + k);
        }
        put_u16(&b, 7); /* flags */
    }
    put_u8(&b, 2); /* note: two chars, then a double */
    put_u8(&b, 'o');
    put_u8(&b, 'k');
    put_f64(&b, 1.5);
    char name[64];
    snprintf(name, sizeof(name), "shapes-%s-%d%d.ply", big ? "be" : "le", count16,
             unsigned_indices);
    FILE *file = fopen(test_path(name), "wb");
    if (file) {
        fwrite(b.data, 1, b.length, file);
        fclose(file);
    }
    rad_scene *scene = load(test_path(name));
    char stem[64];
    snprintf(stem, sizeof(stem), "%.*s", (int)(strlen(name) - 4), name);
    expect_shapes(name, scene, stem, 0.5);
    rad_scene_destroy(scene);

    /* cut anywhere in its body: refused as truncated */
    size_t header_length = strlen(header);
    for (size_t cut = header_length + 1; cut < b.length; cut += 13) {
        file = fopen(test_path("cut.ply"), "wb");
        if (file) {
            fwrite(b.data, 1, cut, file);
            fclose(file);
        }
        rad_scene *cut_scene = NULL;
        rad_error error = {0};
        CHECK(rad_scene_load(test_path("cut.ply"), NULL, &cut_scene, &error) == RAD_ERR_PARSE);
        CHECK(strstr(error.message, ": truncated: the header declares ") != NULL);
        rad_scene_destroy(cut_scene);
    }
}

/* The same shapes in ASCII with comments, obj_info lines and CRLF line endings, an edge
 * element before the faces and a note after them, and the material element's first row. */
static void ascii_shapes(void)
{
    static const char text[] =
        "ply\r\nformat ascii 1.0\r\ncomment made by hand\r\nobj_info scale 1\r\n"
        "element vertex 9\r\nproperty float x\r\nproperty float y\r\ncomment between\r\n"
        "property float z\r\nproperty float nx\r\nelement edge 1\r\nproperty list uchar int "
        "ends\r\nelement face 2\r\nproperty list uchar uint vertex_index\r\n"
        "element material 2\r\nproperty uchar diffuse_red\r\nproperty uchar diffuse_green\r\n"
        "property uchar diffuse_blue\r\nelement note 1\r\nproperty int n\r\nend_header\r\n"
        "0 0 0 1\r\n2 0 0 1\r\n2 1 0 1\r\n0 1 0 1\r\n0 0 1 1\r\n2 0 1 1\r\n3 1 1 1\r\n"
        "1 3 1 1\r\n-1 1 1 1\r\n2 0 1\r\n4 0 1 2 3\r\n5 4 5 6 7 8\r\n51 102 255\r\n"
        "0 0 0\r\n42\r\n";
    rad_scene *scene = load(test_write_file("crlf.ply", text));
    expect_shapes("crlf.ply", scene, "crlf", 0.2);
    if (scene) {
        CHECK_NEAR(scene->materials[0].albedo.g, 0.4, 1e-12);
        CHECK_NEAR(scene->materials[0].albedo.b, 1.0, 1e-12);
        CHECK(strcmp(scene->materials[0].name, "material0") == 0);
    }
    rad_scene_destroy(scene);
    /* PLY content under another extension goes to the same reader */
    scene = load(test_write_file("crlf.scene", text));
    expect_shapes("crlf.scene", scene, "crlf", 0.2);
    rad_scene_destroy(scene);
}

int main(void)
{
    test_tmpdir();
    ascii("rows.ply", HEADER("ascii", "99999999999999999999999", "uchar", "int") VERTICES
                      "3 0 1 2\n",
          ":3: element 'vertex': row count 99999999999999999999999 is out of range");
    ascii("length.ply", ASCII_HEADER VERTICES "99999999999999999999999 0 1 2\n",
          ":13: face 0: list length '99999999999999999999999' is not a count");
    ascii("float-count.ply", HEADER("ascii", "3", "float", "int") VERTICES "3 0 1 2\n",
          ":8: property 'vertex_indices': a list's length is of type 'float', not a whole "
          "number");
    ascii("wraps-to-0.ply", ASCII_HEADER VERTICES "3 4294967296 1 2\n",
          ":13: face 0 refers to vertex 4294967296 but only 3 are defined (PLY counts from 0)");
    ascii("beyond.ply", ASCII_HEADER VERTICES "3 0 1 3\n",
          ":13: face 0 refers to vertex 3 but only 3 are defined (PLY counts from 0)");
    ascii("negative.ply", ASCII_HEADER VERTICES "3 0 -1 2\n",
          ":13: face 0 refers to vertex -1 but only 3 are defined (PLY counts from 0)");
    ascii("int64-min.ply", ASCII_HEADER VERTICES "3 0 1 -9223372036854775808\n",
          ":13: face 0 refers to vertex -9223372036854775808 but only 3 are defined (PLY "
          "counts from 0)");
    ascii("below-min.ply", ASCII_HEADER VERTICES "3 0 1 -99999999999999999999\n",
          ":13: face 0 refers to vertex -99999999999999999999 but only 3 are defined (PLY "
          "counts from 0)");
    ascii("not-whole.ply", ASCII_HEADER VERTICES "3 0 1 2.5\n",
          ":13: face 0: vertex index '2.5' is not a whole number");

    /* binary little-endian: uchar count 3, int indices 0, 1 and -1 (0xffffffff); uint
     * indices 0, 1, 4294967295 */
    for (int is_unsigned = 0; is_unsigned < 2; is_unsigned++) {
        char file[1024];
        int n = snprintf(file, sizeof(file), "%s",
                         is_unsigned ? HEADER("binary_little_endian", "3", "uchar", "uint")
                                     : HEADER("binary_little_endian", "3", "uchar", "int"));
        static const float corners[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
        memcpy(file + n, corners, sizeof(corners)); /* the machine is little-endian */
        n += (int)sizeof(corners);
        static const unsigned char face[13] = {3, 0, 0, 0, 0, 1, 0, 0, 0, 0xff, 0xff, 0xff, 0xff};
        memcpy(file + n, face, sizeof(face));
        n += (int)sizeof(face);
        expect_refused(is_unsigned ? "binary-uint.ply" : "binary-int.ply", file, (size_t)n,
                       is_unsigned ? ": face 0 refers to vertex 4294967295 but only 3 are "
                                     "defined (PLY counts from 0)"
                                   : ": face 0 refers to vertex -1 but only 3 are defined (PLY "
                                     "counts from 0)");
    }

    /* coordinates that are not finite numbers of their type, with their line */
    ascii("nan.ply", ASCII_HEADER "0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n",
          ":11: vertex 1: coordinate y 'nan' is not a finite decimal number");
    ascii("huge.ply", ASCII_HEADER "0 0 0\n1 0 0\n0 1 -1e39\n3 0 1 2\n",
          ":12: vertex 2: coordinate z '-1e39' is beyond the range of float");
    ascii("hex.ply", ASCII_HEADER "0x1p0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
          ":10: vertex 0: coordinate x '0x1p0' is not a finite decimal number");
    /* a row more than declared (the open fuzz findings had one after an empty element) */
    ascii("extra-row.ply", ASCII_HEADER VERTICES "3 0 1 2\n3 0 1 2\n",
          ":14: '3' after the last row the header declares (more rows than declared?)");
    {
        char file[1024];
        int n = snprintf(file, sizeof(file), "%s", HEADER("binary_big_endian", "3", "uchar", "int"));
        static const unsigned char body[] = {0x7f, 0xc0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0}; /* NaN */
        memcpy(file + n, body, sizeof(body));
        expect_refused("binary-nan.ply", file, (size_t)n + sizeof(body),
                       ": vertex 0: coordinate x is not a finite number");
    }

    for (int big = 0; big < 2; big++)
        for (int variant = 0; variant < 2; variant++)
            binary_shapes(big, variant, !variant);
    ascii_shapes();

    /* and a good one still loads */
    rad_scene *scene = NULL;
    rad_error error = {0};
    CHECK(rad_scene_load(test_write_file("good.ply", ASCII_HEADER VERTICES "3 0 1 2\n"), NULL,
                         &scene, &error) == RAD_OK);
    CHECK(scene && scene->triangle_count == 1);
    rad_scene_destroy(scene);
    return test_finish("test_ply_input");
}
