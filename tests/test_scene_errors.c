/*
 * test_scene_errors.c - bad scene files, one test each: a truncated .glb, a glTF whose
 * buffer file is missing, a missing texture (a warning; the albedo falls back to Kd), an
 * accessor index out of range, an empty scene, files that are not scenes at all, and an
 * --emit naming nothing. Each error: one line "radiosity: FILE: ...", exit 1, and no
 * output file (nor temporary file) left behind.
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "testlib.h"

static int count_lines(const char *text)
{
    int lines = 0;
    for (; *text; text++)
        lines += *text == '\n';
    return lines;
}

static void expect_error(const char *case_name, const char *arguments, const char *names)
{
    int code = test_run_tool(arguments);
    const char *err = test_read_text(test_path("stderr.txt"));
    if (code != 1 || count_lines(err) != 1 || strstr(err, names) == NULL)
        fprintf(stderr, "[%s] exit %d, stderr: %s", case_name, code, err);
    CHECK(code == 1);
    CHECK(count_lines(err) == 1);
    CHECK(strncmp(err, "radiosity: ", 11) == 0);
    CHECK(strstr(err, names) != NULL);
    CHECK(test_count_files("out") == 0);
}

/* One triangle as glTF, its buffer as a data URI (3 float positions, 3 uint16 indices). */
static const char *triangle_gltf(const char *buffers, const char *index_accessor)
{
    static char json[4096];
    snprintf(json, sizeof(json),
             "{\"asset\":{\"version\":\"2.0\"},\"scenes\":[{\"nodes\":[0]}],"
             "\"nodes\":[{\"mesh\":0}],\"meshes\":[{\"primitives\":[{\"attributes\":"
             "{\"POSITION\":0},\"indices\":%s}]}],\"buffers\":%s,"
             "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36},{\"buffer\":0,"
             "\"byteOffset\":36,\"byteLength\":6}],\"accessors\":[{\"bufferView\":0,"
             "\"componentType\":5126,\"count\":3,\"type\":\"VEC3\",\"min\":[0,0,0],"
             "\"max\":[1,1,0]},{\"bufferView\":1,\"componentType\":5123,\"count\":3,"
             "\"type\":\"SCALAR\"}]}",
             index_accessor, buffers);
    return json;
}

int main(void)
{
    test_tmpdir();
    /* 0,0,0 1,0,0 0,1,0 as floats, then 0 1 2 as uint16, base64 */
    const char *data = "[{\"byteLength\":42,\"uri\":\"data:application/octet-stream;base64,"
                       "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAABAAIA\"}]";

    /* sanity: the good triangle loads */
    test_write_file("good.gltf", triangle_gltf(data, "1"));
    CHECK(test_run_tool("info good.gltf") == 0);
    CHECK(strstr(test_read_text(test_path("stdout.txt")), "triangles: 1") != NULL);

    /* a truncated .glb: the header's length is longer than the file */
    FILE *file = fopen(test_path("cut.glb"), "wb");
    if (file) {
        const unsigned char header[20] = {'g', 'l', 'T', 'F', 2, 0, 0, 0, 0, 4, 0, 0,
                                          0, 2, 0, 0, 'J', 'S', 'O', 'N'};
        fwrite(header, 1, sizeof(header), file);
        fputs("{\"asset\":{\"version\":\"2.0\"}", file);
        fclose(file);
    }
    expect_error("truncated glb", "render cut.glb -o out.png", "cut.glb: truncated");

    /* a glTF whose buffer file is not there */
    test_write_file("nobin.gltf",
                    triangle_gltf("[{\"byteLength\":42,\"uri\":\"gone%20away.bin\"}]", "1"));
    expect_error("missing buffer", "render nobin.gltf -o out.png",
                 "nobin.gltf: buffer 0: file 'gone%20away.bin' not found");

    /* an accessor index out of range, and an index buffer reaching past its view */
    test_write_file("badaccessor.gltf", triangle_gltf(data, "7"));
    expect_error("accessor out of range", "render badaccessor.gltf -o out.png",
                 "badaccessor.gltf: mesh 0, primitive 0: indices name an accessor out of range");
    test_write_file("shortview.gltf",
                    triangle_gltf("[{\"byteLength\":40,\"uri\":\"data:application/"
                                  "octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAABAA==\"}]",
                                  "1"));
    expect_error("view past buffer", "render shortview.gltf -o out.png",
                 "shortview.gltf: bufferView 1 reaches past the end of buffer 0");

    /* an OBJ face naming a vertex beyond the file's */
    test_write_file("beyond.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n");
    expect_error("obj index", "render beyond.obj -o out.png",
                 "beyond.obj:4: face refers to vertex 9 but only 3 are defined");
    /* relative (negative) indices count back from the face; 0 is no OBJ index */
    test_write_file("relative.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\nf 1/1 2//2 -4\n");
    expect_error("obj relative index", "render relative.obj -o out.png",
                 "relative.obj:5: face refers to vertex -4 (counting back) but only 3 are defined "
                 "above it");
    test_write_file("zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n");
    expect_error("obj index 0", "render zero.obj -o out.png",
                 "zero.obj:4: face refers to vertex 0: OBJ indices start at 1");

    /* empty scenes: a glTF with no meshes, an empty OBJ */
    test_write_file("empty.gltf", "{\"asset\":{\"version\":\"2.0\"},\"scenes\":[{\"nodes\":[]}]}");
    expect_error("empty gltf", "render empty.gltf -o out.png", "empty.gltf:");
    test_write_file("empty.obj", "# nothing here\n");
    expect_error("empty obj", "render empty.obj -o out.png", "empty.obj:");

    /* not a scene at all: a PNG signature under a glb name, prose under a gltf name, an
     * unknown extension */
    test_write_file("photo.glb", "\x89PNG\r\n\x1a\nnot really a picture either");
    expect_error("png as glb", "render photo.glb -o out.png", "photo.glb: not a binary glTF");
    test_write_file("notes.gltf", "Dear diary, today I wrote no JSON.\n");
    expect_error("prose as gltf", "render notes.gltf -o out.png", "notes.gltf: not glTF");
    test_write_file("notes.txt", "Dear diary, today I wrote no scene.\n");
    expect_error("prose", "render notes.txt -o out.png", "notes.txt:");

    /* --emit naming nothing in the scene */
    expect_error("unknown name", "render good.gltf -o out.png --emit lamp=1,1,1",
                 "--emit: ");
    CHECK(strstr(test_read_text(test_path("stderr.txt")), "'lamp'") != NULL);

    /* a missing texture: a warning naming it, and the albedo is Kd */
    test_write_file("tex.mtl", "newmtl painted\nKd 0.25 0.5 0.75\nKe 1 1 1\nmap_Kd nowhere.png\n");
    test_write_file("tex.obj", "mtllib tex.mtl\nusemtl painted\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    CHECK(test_run_tool("info tex.obj") == 0);
    const char *out = test_read_text(test_path("stdout.txt"));
    CHECK(strstr(out, "albedo (0.25, 0.5, 0.75)") != NULL);
    CHECK(strstr(out, "tex.obj: material 'painted': texture 'nowhere.png' not found") != NULL);

    /* PLY files shorter than their header (Assimp 5.2 aborts or crashes on these): the
     * whole file is one triangle, its header declares more rows; a binary one, big-endian
     * (its list count and floats are read in the file's order), loads when complete */
#define PLY_HEADER                                                                         \
    "ply\nformat %s 1.0\nelement vertex %d\nproperty float x\nproperty float y\n"           \
    "property float z\nelement face %d\nproperty list uchar int vertex_indices\nend_header\n"
    char ply[1024];
    snprintf(ply, sizeof(ply), PLY_HEADER, "ascii", 30, 1);
    strcat(ply, "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
    test_write_file("short-vertices.ply", ply);
    expect_error("PLY short of vertices", "render short-vertices.ply -o out.png",
                 "short-vertices.ply:13: row 3 of element 'vertex' does not end its line "
                 "(one row per line; or the file holds fewer rows than its header "
                 "declares)"); /* the face's "3 0 1" read as a 4th vertex leaves "2" */
    snprintf(ply, sizeof(ply), PLY_HEADER, "ascii", 3, 5);
    strcat(ply, "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
    test_write_file("short-faces.ply", ply);
    expect_error("PLY short of faces", "render short-faces.ply -o out.png",
                 "short-faces.ply: truncated: the header declares 5 rows of element 'face', "
                 "the file holds 1");
    snprintf(ply, sizeof(ply), PLY_HEADER, "binary_big_endian", 3, 1);
    size_t header_length = strlen(ply);
    static const unsigned char big_endian_body[] = {
        0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0,          /* (0, 0, 0) */
        0x3f, 0x80, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0,    /* (1, 0, 0) */
        0, 0, 0, 0, 0x3f, 0x80, 0, 0, 0, 0, 0, 0,    /* (0, 1, 0) */
        3, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 2};      /* 3: 0 1 2 */
    memcpy(ply + header_length, big_endian_body, sizeof(big_endian_body));
    for (int cut = 0; cut < 2; cut++) {
        const char *name = cut ? "cut-binary.ply" : "binary.ply";
        FILE *ply_file = fopen(test_path(name), "wb");
        if (ply_file) {
            fwrite(ply, 1, header_length + sizeof(big_endian_body) - (cut ? 4 : 0), ply_file);
            fclose(ply_file);
        }
    }
    CHECK(test_run_tool("info binary.ply") == 0);
    CHECK(strstr(test_read_text(test_path("stdout.txt")), "area 0.5 ") != NULL);
    expect_error("binary PLY cut in its last face", "render cut-binary.ply -o out.png",
                 "cut-binary.ply: truncated: the header declares 1 rows of element 'face', "
                 "the file holds 0");

    /* STL cut short: ASCII between two facets (Assimp 5.2 took what it had), and binary
     * (84 + 50 n bytes), whose header may start with "solid" and still be binary */
    test_write_file("cut-ascii.stl", "solid square\nfacet normal 0 0 1\nouter loop\n"
                                     "vertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\n"
                                     "endfacet\nfacet normal 0 0 1\nouter loop\n");
    expect_error("ASCII STL cut short", "render cut-ascii.stl -o out.png",
                 "cut-ascii.stl: truncated: an ASCII STL ends with 'endsolid', this one with "
                 "'outer loop'");
    unsigned char stl[84 + 2 * 50] = "solid, but binary";
    stl[80] = 2; /* two triangles: (0,0,0) (1,0,0) (0,1,0), and (1,0,0) (1,1,0) (0,1,0) */
    const float corners[2][9] = {{0, 0, 0, 1, 0, 0, 0, 1, 0}, {1, 0, 0, 1, 1, 0, 0, 1, 0}};
    for (int t = 0; t < 2; t++)
        for (int k = 0; k < 9; k++) {
            uint32_t bits;
            memcpy(&bits, &corners[t][k], 4);
            for (int b = 0; b < 4; b++) /* little-endian, after the 12-byte normal */
                stl[84 + 50 * t + 12 + 4 * k + b] = (unsigned char)(bits >> 8 * b);
        }
    for (int cut = 0; cut < 2; cut++) {
        FILE *stl_file = fopen(test_path(cut ? "cut-binary.stl" : "binary.stl"), "wb");
        if (stl_file) {
            fwrite(stl, 1, sizeof(stl) - (cut ? 30 : 0), stl_file);
            fclose(stl_file);
        }
    }
    CHECK(test_run_tool("info binary.stl") == 0);
    CHECK(strstr(test_read_text(test_path("stdout.txt")), "area: 1\n") != NULL);
    expect_error("binary STL cut short", "render cut-binary.stl -o out.png",
                 "cut-binary.stl: truncated or damaged: a binary STL of 2 triangles has 184 "
                 "bytes, this file 154");

    /* the light's power in Ka (as in the wild Cornell box file): a warning naming the
     * material and the --emit that lights it; Ka at most 1 (a reflectance) is no warning */
    test_write_file("ka.mtl", "newmtl bulb\nKa 20 20 20\nKd 1 1 1\n"
                              "newmtl wall\nKa 0.5 0.5 0.5\nKd 0.5 0.5 0.5\n");
    test_write_file("ka.obj", "mtllib ka.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
                              "usemtl bulb\nf 1 2 3\nusemtl wall\nf 1 3 4\n");
    CHECK(test_run_tool("info ka.obj") == 0);
    out = test_read_text(test_path("stdout.txt"));
    CHECK(strstr(out, "warnings: 1\n") != NULL);
    CHECK(strstr(out, "ka.obj: material 'bulb' has an ambient colour Ka (20, 20, 20) above 1 "
                      "but no Ke: it does not emit (--emit bulb=R,G,B makes it a light)") != NULL);
    CHECK(strstr(out, "'wall'") == NULL);
    CHECK(test_run_tool("render ka.obj -o ka.pfm --size 8x8") == 0);
    const char *err = test_read_text(test_path("stderr.txt"));
    CHECK(strstr(err, "material 'bulb' has an ambient colour Ka") != NULL);
    CHECK(strstr(err, "no surface emits light") != NULL && strstr(err, "--emit NAME=R,G,B") != NULL);

    return test_finish("test_scene_errors");
}
