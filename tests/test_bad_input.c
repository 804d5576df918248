/*
 * test_bad_input.c - what a user sees when the input is wrong: one test per case. Every
 * error is one line on stderr, "radiosity: FILE[:LINE]: message", with a non-zero exit,
 * and no output file (nor temporary file) is left behind. Warnings keep the run going.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "testlib.h"

static const char *triangle_mtl = "newmtl lamp\nKd 0.5 0.5 0.5\nKe 1 1 1\n";

static int count_lines(const char *text)
{
    int lines = 0;
    for (; *text; text++)
        lines += *text == '\n';
    return lines;
}

/* Runs the tool; checks exit code, a one-line error naming `names` (and `line_tag` when
 * given, e.g. "bad.obj:3:"), and that no file starting with "out" was left. */
static void expect_error(const char *case_name, const char *arguments, int exit_code,
                         const char *names)
{
    int code = test_run_tool(arguments);
    const char *err = test_read_text(test_path("stderr.txt"));
    if (code != exit_code || count_lines(err) != 1 || strstr(err, names) == NULL ||
        strncmp(err, "radiosity: ", 11) != 0)
        fprintf(stderr, "[%s] exit %d, stderr: %s", case_name, code, err);
    CHECK(code == exit_code);
    CHECK(count_lines(err) == 1);
    CHECK(strncmp(err, "radiosity: ", 11) == 0);
    CHECK(strstr(err, names) != NULL);
    CHECK(test_count_files("out") == 0);
}

/* The last line of text (without its newline) in a static buffer; "" when there is none. */
static const char *last_line(const char *text)
{
    static char line[4096];
    size_t length = strlen(text);
    if (length > 0 && text[length - 1] == '\n')
        length--;
    size_t start = length;
    while (start > 0 && text[start - 1] != '\n')
        start--;
    snprintf(line, sizeof(line), "%.*s", (int)(length - start), text + start);
    return line;
}

/* Every run ends with its one-line summary on stderr, terminal or not (stderr is a file
 * here), naming what it wrote; --quiet leaves it out, and then a clean run says nothing. */
static void expect_summary(const char *arguments, const char *written)
{
    char command[1024], wrote[256];
    snprintf(wrote, sizeof(wrote), "wrote %s", written);
    int code = test_run_tool(arguments);
    const char *line = last_line(test_read_text(test_path("stderr.txt")));
    if (code != 0 || strncmp(line, "radiosity: ", 11) != 0 || !strstr(line, wrote))
        fprintf(stderr, "[%s] exit %d, last line of stderr: %s\n", arguments, code, line);
    CHECK(code == 0);
    CHECK(strncmp(line, "radiosity: ", 11) == 0);
    CHECK(strstr(line, wrote) != NULL);
    CHECK(strncmp(line, "radiosity: warning:", 19) != 0);
    snprintf(command, sizeof(command), "%s --quiet", arguments);
    code = test_run_tool(command);
    const char *err = test_read_text(test_path("stderr.txt"));
    if (code != 0 || err[0] != 0)
        fprintf(stderr, "[%s] exit %d, stderr: %s\n", command, code, err);
    CHECK(code == 0);
    CHECK(err[0] == 0);
}

int main(void)
{
    test_write_file("lamp.mtl", triangle_mtl);

    /* a missing scene file */
    expect_error("missing file", "render missing.obj -o out.png", 1, "missing.obj: cannot open");

    /* a garbled OBJ: binary noise */
    test_write_file("garbled.obj", "\x01\x02\x03garbage\xff\xfe\n\x7f" "ELF\n#\n");
    expect_error("garbled", "render garbled.obj -o out.png", 1, "garbled.obj:");

    /* a face that names a vertex that does not exist */
    test_write_file("badindex.obj", "v 0 0 0\nv 1 0 0\nf 1 2 3\n");
    expect_error("index", "render badindex.obj -o out.png", 1,
                 "badindex.obj:3: face refers to vertex 3 but only 2 are defined");

    /* a material library that is not there: file and line */
    test_write_file("nomtl.obj", "# a comment\nmtllib nowhere.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    expect_error("missing mtl", "render nomtl.obj -o out.png", 1, "nomtl.obj:2: material library 'nowhere.mtl'");

    /* NaN and infinite coordinates: file and line */
    test_write_file("nan.obj", "mtllib lamp.mtl\nv 0 0 0\nv 1 nan 0\nv 0 1 0\nusemtl lamp\nf 1 2 3\n");
    expect_error("nan", "render nan.obj -o out.png", 1, "nan.obj:3:");
    test_write_file("inf.obj", "mtllib lamp.mtl\nv 0 0 0\nv 1 0 0\nv 0 -inf 0\nusemtl lamp\nf 1 2 3\n");
    expect_error("inf", "render inf.obj -o out.png", 1, "inf.obj:4:");

    /* a folder where a scene file should be */
    expect_error("folder as scene", "render . -o out.png", 1, ".: cannot open: not a file");

    /* a coordinate finite in double but not in single precision, and a scene too small to
     * trace in single precision */
    test_write_file("huge.obj", "v 0 0 0\nv 1e300 0 0\nv 0 1 0\nf 1 2 3\n");
    expect_error("huge", "render huge.obj -o out.png", 1, "huge.obj:2:");
    test_write_file("tiny.obj", "v 0 0 0\nv 1e-20 0 0\nv 0 1e-20 0\nf 1 2 3\n");
    expect_error("tiny", "render tiny.obj -o out.png", 1, "tiny.obj: the scene spans");

    /* an unknown option is a usage error */
    expect_error("unknown option", "render --brightness 3 -o out.png", 2, "--brightness");
    expect_error("unknown command", "paint -o out.png", 2, "paint");
    expect_error("bad value", "render -o out.png --size 12by4", 2, "--size");

    /* an output path that cannot be written: checked before any work, nothing left */
    expect_error("unwritable", "render -o no/such/folder/out.png", 1, "no/such/folder/out.png");
    expect_error("unknown format", "render -o out.jpg", 2, "out.jpg");
    if (system("mkdir -p '" RAD_TEST_TMP "/folder.png'") != 0)
        test_fail(__FILE__, __LINE__, "mkdir failed");
    expect_error("output is a folder", "render -o folder.png", 1, "folder.png: cannot write: it is a folder");
    expect_error("stats is a folder", "render -o out.png --stats folder.png", 1, "folder.png");

    /* no emitter: a warning, a black image, success */
    test_write_file("dark.mtl", "newmtl grey\nKd 0.5 0.5 0.5\n");
    test_write_file("dark.obj", "mtllib dark.mtl\nusemtl grey\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    int code = test_run_tool("render dark.obj -o dark.pfm --size 16x16 --eye 0.3,0.3,1 "
                             "--target 0.3,0.3,0");
    CHECK(code == 0);
    CHECK(strstr(test_read_text(test_path("stderr.txt")), "warning: dark.obj: no surface emits") != NULL);
    rad_image *image = NULL;
    rad_error error;
    CHECK(rad_image_read(test_path("dark.pfm"), &image, &error) == RAD_OK);
    if (image) {
        int lit = 0;
        for (size_t k = 0; k < (size_t)image->width * image->height * 3; k++)
            lit += image->rgb[k] != 0;
        CHECK(lit == 0);
        rad_image_destroy(image);
    }

    /* a closed room seen from outside (the default view): every surface shows its back,
     * the image is black although the room is lit: a warning says where to put the camera;
     * from inside, no warning */
    test_write_furnace("room.obj");
    code = test_run_tool("render room.obj -o room.pfm --size 16x16 --patch-size 0.5");
    CHECK(code == 0);
    CHECK(strstr(test_read_text(test_path("stderr.txt")),
                 "warning: room.obj: the image is black: the camera at (0.5, 0.5, ") != NULL);
    code = test_run_tool("render room.obj -o room.pfm --size 16x16 --patch-size 0.5 "
                         "--eye 0.5,0.5,0.9 --target 0.5,0.5,0");
    CHECK(code == 0);
    CHECK(strstr(test_read_text(test_path("stderr.txt")), "the image is black") == NULL);

    /* degenerate triangles: skipped with a warning naming how many and where */
    test_write_file("degenerate.obj",
                    "mtllib lamp.mtl\nusemtl lamp\no panel\n"
                    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\n"
                    "f 1 2 3\nf 1 3 4\nf 1 2 5\nf 2 2 3\n");
    code = test_run_tool("render degenerate.obj -o degenerate.pfm --size 16x16 "
                         "--eye 0.5,0.5,1 --target 0.5,0.5,0");
    CHECK(code == 0);
    CHECK(strstr(test_read_text(test_path("stderr.txt")),
                 "degenerate.obj: surface 'panel': 2 degenerate triangles skipped") != NULL);
    image = NULL;
    CHECK(rad_image_read(test_path("degenerate.pfm"), &image, &error) == RAD_OK);
    if (image) {
        /* the panel itself still renders: the centre pixel shows its emission (1) at least */
        float centre = image->rgb[((size_t)8 * 16 + 8) * 3];
        CHECK(centre >= 1.0f);
        rad_image_destroy(image);
    }

    /* a scene with nothing but degenerate triangles is an error */
    test_write_file("flat.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n");
    expect_error("all degenerate", "render flat.obj -o out.png", 1, "flat.obj:");

    /* viewfactors: the same discipline */
    expect_error("viewfactors missing", "viewfactors missing.obj -o out.csv", 1, "missing.obj");
    expect_error("viewfactors unwritable", "viewfactors nan.obj -o no/dir/out.csv", 1,
                 "no/dir/out.csv");
    /* the summary line of every command that writes, and --quiet */
    test_write_file("plates.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                                  "v 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
                                  "o floor\nf 1 2 3 4\no roof\nf 5 8 7 6\n");
    expect_summary("render -o sum.pfm --size 8x8 --patch-size 200", "sum.pfm");
    expect_summary("solve -o sum.ply --patch-size 200", "sum.ply");
    expect_summary("raytrace -o sum.pfm --size 8x8", "sum.pfm");
    expect_summary("pathtrace -o sum.pfm --size 8x8 --spp 2", "sum.pfm");
    expect_summary("viewfactors plates.obj -o sum.csv", "sum.csv");
    expect_summary("info -o sum.txt", "sum.txt");
    /* --quiet keeps the warnings */
    code = test_run_tool("pathtrace dark.obj -o sum.pfm --size 8x8 --spp 2 --quiet");
    CHECK(code == 0);
    const char *err = test_read_text(test_path("stderr.txt"));
    CHECK(strstr(err, "warning: dark.obj: no surface emits") != NULL);
    CHECK(count_lines(err) == 1);

    return test_finish("test_bad_input");
}
