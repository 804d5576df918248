/*
 * test_memory_budget.c - --max-memory bounds the run's large buffers, and a run that
 * cannot fit is refused before its work with one line giving the need and the budget.
 *
 * The built-in Cornell box at patch size 30 has n patches (counted here with
 * rad_mesh_build); its dense matrix is 4 n^2 bytes (12 n^2 for the direct solver, whose
 * LU copy is in doubles); a W x H image is 12 W H bytes, plus 8 W H for a PNG's automatic
 * exposure. With a 16 x 16 PFM (3072 bytes) the test puts the budget one byte either side
 * of image + matrix:
 *   - gather asked for, budget = image + 4 n^2 - 1: refused, the exact line;
 *   - gather asked for, budget = image + 4 n^2: runs, gather;
 *   - no solver asked for, budget = image + 4 n^2 - 1: the automatic choice goes
 *     hierarchical and says why;
 *   - direct asked for, budget = image + 8 n^2: refused, 12 n^2;
 *   - the image alone over the budget: 1000 x 1000 PNG 20,000,000 bytes, PFM 12,000,000;
 *   - the tracers: a 1000 x 1000 PNG over 15 MB, a path-traced PFM with its standard
 *     error (24,000,000 bytes) over 20 MB; the PFM alone (12,000,000) runs in 12 MB;
 *   - hierarchical with 1 MB: its trees do not fit, refused.
 */
#include <stdio.h>
#include <string.h>

#include "testlib.h"

#define IMAGE_BYTES (16 * 16 * 12)

static int run(const char *arguments)
{
    int code = test_run_tool(arguments);
    if (code != 0)
        printf("[%s] exit %d: %s", arguments, code, test_read_text(test_path("stderr.txt")));
    return code;
}

/* The run is refused: exit 1, exactly `expected` on stderr, no output written. */
static void expect_refused(const char *arguments, const char *expected)
{
    int code = test_run_tool(arguments);
    const char *err = test_read_text(test_path("stderr.txt"));
    if (code != 1 || strcmp(err, expected) != 0)
        fprintf(stderr, "[%s] exit %d:\n  got      %s  expected %s", arguments, code, err,
                expected);
    CHECK(code == 1);
    CHECK(strcmp(err, expected) == 0);
    CHECK(test_count_files("out") == 0);
}

int main(void)
{
    test_tmpdir();
    rad_scene *scene = NULL;
    rad_mesh *mesh = NULL;
    rad_error error = {0};
    CHECK(rad_scene_cornell_box(&scene, &error) == RAD_OK);
    CHECK(scene && rad_mesh_build(scene, 30, &mesh, &error) == RAD_OK);
    if (!mesh)
        return test_finish("test_memory_budget");
    unsigned long long n = mesh->patch_count;
    unsigned long long matrix = 4 * n * n;
    printf("Cornell box at patch size 30: %llu patches, dense matrix %llu bytes\n", n, matrix);
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene);

    char arguments[512], expected[512];
    const char *common =
        "render -o out.pfm --size 16x16 --spp 1 --patch-size 30 --stats stats.json";
    /* gather, one byte short */
    snprintf(arguments, sizeof(arguments), "%s --solver gather --max-memory %llu", common,
             IMAGE_BYTES + matrix - 1);
    snprintf(expected, sizeof(expected),
             "radiosity: --max-memory: the gather solver's matrix for %llu patches needs %.1f MB "
             "(4 n^2 bytes), more than the budget of %.1f MB: use a larger --patch-size, the "
             "hierarchical solver or a larger budget\n",
             n, matrix / 1048576.0, (matrix - 1) / 1048576.0);
    expect_refused(arguments, expected);

    /* gather, exactly enough */
    snprintf(arguments, sizeof(arguments), "%s --solver gather --max-memory %llu", common,
             IMAGE_BYTES + matrix);
    CHECK(run(arguments) == 0);
    CHECK(strstr(test_read_text(test_path("stats.json")), "\"solver\": \"gather\"") != NULL);
    CHECK(test_file_exists(test_path("out.pfm")));
    remove(test_path("out.pfm"));

    /* the automatic choice, one byte short of the matrix: hierarchical, and why */
    snprintf(arguments, sizeof(arguments), "%s --max-memory %llu", common,
             IMAGE_BYTES + matrix - 1);
    CHECK(run(arguments) == 0);
    const char *stats = test_read_text(test_path("stats.json"));
    CHECK(strstr(stats, "\"solver\": \"hierarchical\"") != NULL);
    CHECK(strstr(stats, "\"solver_chosen\": true") != NULL);
    char reason[160];
    snprintf(reason, sizeof(reason),
             "\"solver_reason\": \"the %.1f MB matrix would not fit --max-memory (%.1f MB)\"",
             matrix / 1048576.0, (matrix - 1) / 1048576.0);
    CHECK(strstr(stats, reason) != NULL);
    remove(test_path("out.pfm"));
    remove(test_path("stats.json"));

    /* direct: the LU copy triples the need */
    snprintf(arguments, sizeof(arguments), "%s --solver direct --max-memory %llu", common,
             IMAGE_BYTES + 2 * matrix);
    snprintf(expected, sizeof(expected),
             "radiosity: --max-memory: the direct solver's matrix for %llu patches needs %.1f MB "
             "(12 n^2 bytes), more than the budget of %.1f MB: use a larger --patch-size, the "
             "hierarchical solver or a larger budget\n",
             n, 3 * matrix / 1048576.0, 2 * matrix / 1048576.0);
    expect_refused(arguments, expected);

    /* the image alone: 20 bytes a pixel as PNG with automatic exposure, 12 as PFM or with a
     * fixed exposure */
    expect_refused("render -o out.png --size 1000x1000 --max-memory 10M",
                   "radiosity: --max-memory: the 1000 x 1000 image needs 19.1 MB, more than the "
                   "budget of 10.0 MB\n");
    expect_refused("render -o out.pfm --size 1000x1000 --max-memory 10M",
                   "radiosity: --max-memory: the 1000 x 1000 image needs 11.4 MB, more than the "
                   "budget of 10.0 MB\n");
    expect_refused("render -o out.png --exposure 0 --size 1000x1000 --max-memory 10M",
                   "radiosity: --max-memory: the 1000 x 1000 image needs 11.4 MB, more than the "
                   "budget of 10.0 MB\n");

    /* the tracers: their images (the path tracer's standard error is one more) */
    expect_refused("raytrace -o out.png --size 1000x1000 --max-memory 15M",
                   "radiosity: --max-memory: the 1000 x 1000 image needs 19.1 MB, more than the "
                   "budget of 15.0 MB\n");
    expect_refused("pathtrace -o out.pfm --standard-error out-error.pfm --size 1000x1000 "
                   "--max-memory 20M",
                   "radiosity: --max-memory: the 1000 x 1000 image with its standard error "
                   "needs 22.9 MB, more than the budget of 20.0 MB\n");
    CHECK(run("pathtrace -o out.pfm --size 1000x1000 --spp 1 --max-depth 1 --max-memory 12M") ==
          0);
    remove(test_path("out.pfm"));

    /* hierarchical: the trees come first */
    snprintf(arguments, sizeof(arguments), "%s --solver hierarchical --max-memory 1M", common);
    int code = test_run_tool(arguments);
    const char *err = test_read_text(test_path("stderr.txt"));
    snprintf(expected, sizeof(expected),
             "radiosity: --max-memory: the element and cluster trees of %llu patches need up "
             "to ",
             n);
    CHECK(code == 1);
    CHECK(strncmp(err, expected, strlen(expected)) == 0);
    CHECK(strstr(err, "MB, more than the budget of 1.0 MB\n") != NULL);
    CHECK(test_count_files("out") == 0);
    return test_finish("test_memory_budget");
}
