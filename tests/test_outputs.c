/*
 * test_outputs.c - every output a command would write is checked before any work: an
 * output that cannot be created or replaced is one line naming it, and exit status 1.
 *
 * Each command is given an input that does not exist: were the outputs checked after the
 * input is read (let alone after solving or rendering), the message would be about the
 * input. For every output option of every command that writes files (render, solve,
 * viewfactors, raytrace, pathtrace, compare, info: -o, --stats, --save-solution,
 * --standard-error) the output is put where it cannot be written:
 *   - under a regular file ("afile/out.x"): not a folder, which even root cannot write;
 *   - on an existing folder ("folder.x"): it is a folder;
 *   - under a folder that does not exist ("nodir/out.x");
 *   - in a read-only folder ("readonly/out.x"), when not run as root (root writes there).
 * Nothing may be left in the scratch folder but what the test made.
 */
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "testlib.h"

typedef struct output_case {
    const char *before, *after; /* the arguments before and after the output */
    const char *extension;
} output_case;

static const output_case cases[] = {
    {"render missing.obj -o ", "", "png"},
    {"render missing.obj -o fine.png --stats ", "", "json"},
    {"render missing.obj -o fine.png --save-solution ", "", "sol"},
    {"solve missing.obj -o ", "", "ply"},
    {"solve missing.obj -o fine.ply --stats ", "", "json"},
    {"solve missing.obj --save-solution ", "", "sol"},
    {"viewfactors missing.obj -o ", "", "csv"},
    {"viewfactors missing.obj -o fine.csv --stats ", "", "json"},
    {"raytrace missing.obj -o ", "", "png"},
    {"raytrace missing.obj -o fine.png --stats ", "", "json"},
    {"pathtrace missing.obj -o ", "", "pfm"},
    {"pathtrace missing.obj -o fine.pfm --stats ", "", "json"},
    {"pathtrace missing.obj -o fine.pfm --standard-error ", "", "pfm"},
    {"compare missing-a.pfm missing-b.pfm -o ", "", "png"},
    {"compare missing-a.pfm missing-b.pfm --stats ", "", "json"},
    {"info missing.obj -o ", "", "txt"},
    {"info missing.obj --stats ", "", "json"},
};

static int count_lines(const char *text)
{
    int lines = 0;
    for (; *text; text++)
        lines += *text == '\n';
    return lines;
}

/* Runs the case with `output`; expects exit 1 and exactly the line "radiosity: <output>:
 * cannot write: <why>". */
static void expect_refusal(const output_case *c, const char *output, const char *why)
{
    char arguments[512], expected[512];
    snprintf(arguments, sizeof(arguments), "%s%s%s", c->before, output, c->after);
    snprintf(expected, sizeof(expected), "radiosity: %s: cannot write: %s\n", output, why);
    int code = test_run_tool(arguments);
    const char *err = test_read_text(test_path("stderr.txt"));
    if (code != 1 || strcmp(err, expected) != 0)
        fprintf(stderr, "[%s] exit %d, stderr: %s(expected %s)", arguments, code, err,
                expected);
    CHECK(code == 1);
    CHECK(count_lines(err) == 1);
    CHECK(strcmp(err, expected) == 0);
    CHECK(test_count_files("fine") == 0);
}

int main(void)
{
    test_tmpdir();
    test_write_file("afile", "a regular file\n");
    CHECK(mkdir(test_path("readonly"), 0555) == 0);
    bool root = geteuid() == 0;
    if (root)
        printf("running as root: the read-only folder case is skipped (root writes "
               "there)\n");
    int refusals = 0;
    for (size_t k = 0; k < sizeof(cases) / sizeof(cases[0]); k++) {
        const output_case *c = &cases[k];
        char path[128];
        snprintf(path, sizeof(path), "afile/out.%s", c->extension);
        expect_refusal(c, path, "'afile' is not a folder");
        snprintf(path, sizeof(path), "folder.%s", c->extension);
        mkdir(test_path(path), 0755); /* shared by the cases of one extension */
        expect_refusal(c, path, "it is a folder");
        snprintf(path, sizeof(path), "nodir/out.%s", c->extension);
        expect_refusal(c, path, "folder 'nodir' does not exist");
        refusals += 3;
        if (!root) {
            snprintf(path, sizeof(path), "readonly/out.%s", c->extension);
            expect_refusal(c, path, "folder 'readonly' is not writable (Permission denied)");
            refusals++;
        }
    }
    CHECK(test_count_files("nodir") == 0);
    CHECK(test_count_files("out") == 0);
    printf("%d refusals checked over %zu command and option pairs\n", refusals,
           sizeof(cases) / sizeof(cases[0]));
    chmod(test_path("readonly"), 0755); /* so that the next run can empty the folder */
    return test_finish("test_outputs");
}
