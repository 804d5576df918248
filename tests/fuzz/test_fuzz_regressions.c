/*
 * test_fuzz_regressions.c - every input the fuzz targets (or the wild corpus) found a
 * crash, leak, broken contract or wrong refusal with (tests/fuzz/regressions/, also in the
 * targets' seed corpora), through the
 * command line: `radiosity info FILE` exits 1 with one line "radiosity: FILE...: message"
 * on stderr (no control character in it), or (the inputs that are valid) loads, with a
 * warning where a value was dropped and no non-finite number in what it prints.
 */
#include <ctype.h>
#include <stdio.h>
#include <string.h>

#include "testlib.h"

/* One line: a newline at the end and no other control character (a carriage return
 * would put the rest of the message over its start on a terminal). */
static bool one_clean_line(const char *text)
{
    size_t n = strlen(text);
    if (n == 0 || text[n - 1] != '\n')
        return false;
    for (size_t k = 0; k + 1 < n; k++)
        if ((unsigned char)text[k] < 0x20 || text[k] == 0x7f)
            return false;
    return true;
}

/* True when text holds "inf" or "nan" as a word (a number printed with %g), not inside a
 * name such as "mtl_infinite". */
static bool prints_non_finite(const char *text)
{
    for (const char *p = text; *p; p++)
        if ((strncmp(p, "inf", 3) == 0 || strncmp(p, "nan", 3) == 0) &&
            (p == text || (!isalnum((unsigned char)p[-1]) && p[-1] != '_')) &&
            !isalnum((unsigned char)p[3]) && p[3] != '_')
            return true;
    return false;
}

/* `radiosity info regressions/NAME` is refused: exit 1, one line naming the file (and
 * `fragment` from the message). */
static void expect_refused(const char *name, const char *fragment)
{
    char arguments[4096], named[1024];
    snprintf(arguments, sizeof(arguments), "info '%s/%s'", RAD_FUZZ_REGRESSIONS, name);
    snprintf(named, sizeof(named), "radiosity: %s/%s", RAD_FUZZ_REGRESSIONS, name);
    int code = test_run_tool(arguments);
    const char *err = test_read_text(test_path("stderr.txt"));
    if (code != 1 || !one_clean_line(err) || strncmp(err, named, strlen(named)) != 0 ||
        !strstr(err, fragment))
        fprintf(stderr, "[%s] exit %d, stderr: %s\n", name, code, err);
    CHECK(code == 1);
    CHECK(one_clean_line(err));
    CHECK(strncmp(err, named, strlen(named)) == 0);
    CHECK(strstr(err, fragment) != NULL);
}

/* `radiosity info regressions/NAME` loads: exit 0, `fragment` in what it prints, and no
 * non-finite number. */
static void expect_loads(const char *name, const char *fragment)
{
    char arguments[4096];
    snprintf(arguments, sizeof(arguments), "info '%s/%s'", RAD_FUZZ_REGRESSIONS, name);
    int code = test_run_tool(arguments);
    const char *out = test_read_text(test_path("stdout.txt"));
    bool found = strstr(out, fragment) != NULL, finite = !prints_non_finite(out);
    if (code != 0 || !found || !finite)
        fprintf(stderr, "[%s] exit %d, stderr: %s\nstdout: %s\n", name, code,
                test_read_text(test_path("stderr.txt")), out);
    CHECK(code == 0);
    CHECK(found);
    CHECK(finite);
}

int main(void)
{
    /* Assimp aborted (ai_assert in its triangulation) */
    expect_refused("ply_empty_face.ply", "face 0 has no vertices");
    expect_refused("ply_unnamed_property.ply", ":5: bad property line");
    /* Assimp 5.2 corrupted its heap after skipping a header line it did not know */
    expect_refused("ply_unknown_header_word.ply", ":4: unknown header line 'pro3'");
    /* Assimp 5.2 aborted after a header line that began with NUL bytes */
    expect_refused("ply_nul_header_line.ply", ":6: header line holds a NUL byte");
    /* Assimp 5.2 aborted on an ASCII row whose line ended in a form feed, not a newline */
    expect_refused("ply_rows_run_together.ply", "row 2 of element 'vertex' does not end its line");
    /* Assimp 5.2 aborted on ASCII values "0-" and "25" + NUL */
    expect_refused("ply_bad_number.ply", ":15: vertex 0: '0-' is not a number");
    /* 4294967295 rows without properties: minutes in the pre-check, then Assimp spun */
    expect_refused("ply_rows_without_properties.ply",
                   "element 'face' declares 4294967295 rows but no properties");
    /* no element at all: Assimp 5.2 crashed (SEGV) */
    expect_refused("ply_no_elements.ply", ":2: PLY version '1.0ledices'");
    /* Assimp 5.2 aborted on these CRLF files (an LF CR line end; found by fuzz_ply, kept
     * open until the project read PLY itself): the row after an empty material element
     * is one more than the header declares */
    expect_refused("ply_ci_finding.ply", ":19: '0.5' after the last row the header declares");
    expect_refused("ply_cr_line_start.ply", ":19: '0.5' after the last row the header declares");
    /* signed overflow negating the index -2^63 */
    expect_refused("obj_index_min.obj", "obj_index_min.obj:3: ");
    /* Assimp failed the OBJ ("File is too small") and leaked */
    expect_refused("mtl_tiny.obj", ":1: material library 'mtl_tiny.mtl' has 1 bytes");
    /* Assimp crashed (SEGV) on a texture statement hidden behind NUL bytes */
    expect_refused("mtl_nul_bytes.obj",
                   ":1: material library 'mtl_nul_bytes.mtl' holds a NUL byte: not a text file");
    /* Assimp crashed (SEGV) on a statement before the first newmtl */
    expect_refused("mtl_before_newmtl.obj",
                   ":1: material library 'mtl_before_newmtl.mtl', line 1: '[ewmtl' before");
    /* the message quoted a newline from the input */
    expect_refused("gltf_uri_newline.gltf", "buffer 0: file 'dat{},?' not found");
    expect_refused("stl_tail_control.stl", "truncated: an ASCII STL ends with 'endsolid'");

    /* Ke 1 inf 1e308 (beyond float: inf in Assimp): a warning, the emission 0 */
    char arguments[4096];
    snprintf(arguments, sizeof(arguments), "info '%s/mtl_infinite.obj'", RAD_FUZZ_REGRESSIONS);
    int code = test_run_tool(arguments);
    const char *err = test_read_text(test_path("stderr.txt"));
    const char *out = test_read_text(test_path("stdout.txt"));
    if (code != 0 || strstr(out, "emission (1, 0, 0)") == NULL || prints_non_finite(out))
        fprintf(stderr, "[mtl_infinite.obj] exit %d, stderr: %s\nstdout: %s\n", code, err, out);
    CHECK(code == 0);
    CHECK(strstr(out, "material 'lamp': negative or invalid emission set to 0") != NULL);
    CHECK(strstr(out, "emission (1, 0, 0)") != NULL);
    CHECK(!prints_non_finite(out));
    CHECK(prints_non_finite("radiance (inf, 0, 0)")); /* the scans themselves */
    CHECK(!one_clean_line("radiosity: a.stl: ends with 'x\r'\n"));
    /* found by the wild corpus (tests/wild): ASCII STL files refused as damaged binary
     * ones (a UTF-8 solid name), or as truncated (a last line longer than 255 bytes, CR
     * line endings); an emission beyond single precision printed as inf */
    expect_loads("stl_name_utf8.stl", "triangles: 2");
    expect_loads("stl_name_long.stl", "triangles: 2");
    expect_loads("stl_ascii_cr.stl", "triangles: 2");
    expect_loads("gltf_strength_huge.gltf", "negative or invalid emission set to 0");
    /* a vertex or surface number of 4e9 made the View3D reader allocate 96 or 16 GB
     * (out of memory, or an abort under AddressSanitizer) */
    expect_refused("vs3_vertex_number_huge.vs3",
                   ":12: vertex number 4000000000 is larger than this reader supports");
    expect_refused("vs3_surface_number_huge.vs3",
                   ":18: surface number 4000000000 is larger than this reader supports");
    /* Assimp 5.2 skips an indented OBJ line: the face was lost in silence */
    /* Assimp 5.2 skips indented lines: the copy it reads has them unindented */
    expect_loads("obj_indented_face.obj", "triangles: 2");
    return test_finish("test_fuzz_regressions");
}
