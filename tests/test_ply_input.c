/*
 * test_ply_input.c - the PLY pre-check of rad_scene_load on integers: a row count or a
 * list length beyond 64 bits (refused as such, not as a file "holding" 2^64 - 1 rows), a
 * list length of a floating type, and face vertex indices outside the vertex list, in
 * ASCII and in binary (Assimp 5.2 keeps an index's low 32 bits: 4294967296 would be
 * vertex 0 without a word). Each message is the exact text.
 */
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

    /* and a good one still loads */
    rad_scene *scene = NULL;
    rad_error error = {0};
    CHECK(rad_scene_load(test_write_file("good.ply", ASCII_HEADER VERTICES "3 0 1 2\n"), NULL,
                         &scene, &error) == RAD_OK);
    CHECK(scene && scene->triangle_count == 1);
    rad_scene_destroy(scene);
    return test_finish("test_ply_input");
}
