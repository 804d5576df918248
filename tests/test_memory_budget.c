/*
 * test_memory_budget.c - --max-memory bounds the whole run (rad_memory_budget_set): a run
 * whose known buffers cannot fit is refused before its work with one line giving the need,
 * what is left and the budget; any other step that would exceed it ends the run with an
 * error naming the budget, exit 1 and no output; a budget at the run's need succeeds and
 * the process's peak resident size stays under the budget plus a fixed overhead.
 *
 * In process: rad_image_create past the budget fails with RAD_ERR_NOMEM and the refusal
 * names its 12 W H bytes; reservations take exactly their bytes from what is left; a BVH
 * build is cancelled by Embree's memory monitor (RAD_ERR_NOMEM, no leak) when it would
 * pass the budget, and runs with enough.
 *
 * Up front (the Cornell box at patch size 30 has n patches, counted with rad_mesh_build):
 *   - gather with a budget of 4 n^2 + 1 MB: the 4 n^2-byte matrix does not fit what the
 *     scene, mesh and image leave, refused with the line; the automatic choice then goes
 *     hierarchical and says why; direct with 8 n^2: its 12 n^2 refused;
 *   - images: a 1000 x 1000 PNG with automatic exposure is 20,000,000 bytes, a PFM
 *     12,000,000; a path-traced PFM with its standard error 24,000,000;
 *   - viewfactors on a K x K grid of floor cells under a K x K grid of ceiling cells (each
 *     cell one surface, a View3D file): K^4 floor-ceiling pairs face each other
 *     (coplanar ones face away), so the matrix's bound is 24 K^4 + 20 (2 K^4) +
 *     16 (2 K^2 + 1) bytes;
 *   - the light at the vertices after the solve (864 bytes a patch), before the solve;
 *   - hierarchical: its trees first.
 * Each command (render, solve, viewfactors, pathtrace, raytrace, illuminance; the
 * solvers with gather on the Cornell box at patch size 45, the grid for viewfactors) with
 * one thread: run with a large budget, its --stats give the budget's high-water mark P (the
 * most in use, reserved and asked for at a check) and the peak resident size; then
 * P - MARGIN is refused (exit 1, one line naming --max-memory, no output file) and
 * P + MARGIN succeeds with its peak resident size at most P + MARGIN + OVERHEAD. MARGIN
 * covers what Embree's parallel BVH build changes from run to run (a few KB measured);
 * OVERHEAD is what the budget does not count: the program's code and the shared
 * libraries' (Embree, Assimp, OpenEXR, libstdc++), thread stacks and heap memory freed
 * but kept by malloc (a run with a 16-patch scene resides in 13.1 MB, 0.2 MB of it
 * counted).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "testlib.h"

/* Under AddressSanitizer the process also holds shadow memory and a quarantine of freed
 * blocks: the resident size says nothing of the budget there, and is not checked. */
#if defined(__SANITIZE_ADDRESS__)
#define RESIDENT_CHECKED 0
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define RESIDENT_CHECKED 0
#endif
#endif
#ifndef RESIDENT_CHECKED
#define RESIDENT_CHECKED 1
#endif

#define MARGIN (64ull * 1024)
#define OVERHEAD (16ull * 1024 * 1024)
#define GRID 16 /* viewfactors: GRID x GRID cells on the floor and on the ceiling */

static int run(const char *arguments)
{
    int code = test_run_tool(arguments);
    if (code != 0)
        printf("[%s] exit %d: %s", arguments, code, test_read_text(test_path("stderr.txt")));
    return code;
}

/* The value of "key": N in the --stats file stats.json, 0 when absent. */
static unsigned long long stats_value(const char *key)
{
    char pattern[96];
    snprintf(pattern, sizeof(pattern), "\"%s\": ", key);
    const char *at = strstr(test_read_text(test_path("stats.json")), pattern);
    return at ? strtoull(at + strlen(pattern), NULL, 10) : 0;
}

/* stderr is the one line `prefix` ... `suffix`; the run exited 1 and wrote nothing. */
static void expect_refused(const char *arguments, const char *prefix, const char *suffix)
{
    int code = test_run_tool(arguments);
    const char *err = test_read_text(test_path("stderr.txt"));
    size_t length = strlen(err);
    bool match = strncmp(err, prefix, strlen(prefix)) == 0 && length >= strlen(suffix) &&
                 strcmp(err + length - strlen(suffix), suffix) == 0 &&
                 strchr(err, '\n') == err + length - 1;
    if (code != 1 || !match)
        fprintf(stderr, "[%s] exit %d:\n  got      %s  expected %s...%s", arguments, code, err,
                prefix, suffix);
    CHECK(code == 1);
    CHECK(match);
    CHECK(test_count_files("out") == 0);
}

static void remove_outputs(void)
{
    const char *names[] = {"out.pfm", "out.ply", "out.csv", "out.png", "stats.json"};
    for (size_t k = 0; k < sizeof(names) / sizeof(names[0]); k++)
        remove(test_path(names[k]));
}

/* The command needs P (its high-water mark with a large budget): P - MARGIN is refused,
 * P + MARGIN runs within it. */
static void check_command(const char *name, const char *arguments, const char *output)
{
    char command[1024];
    snprintf(command, sizeof(command), "%s --max-memory 4G --stats stats.json", arguments);
    CHECK(run(command) == 0);
    unsigned long long need = stats_value("memory_budget_peak_bytes");
    CHECK(stats_value("memory_budget_bytes") == 4ull << 30);
    CHECK(need > MARGIN);
    remove_outputs();

    snprintf(command, sizeof(command), "%s --max-memory %llu --stats stats.json", arguments,
             need - MARGIN);
    int code = test_run_tool(command);
    const char *err = test_read_text(test_path("stderr.txt"));
    printf("%-11s budget %llu: exit %d: %s", name, need - MARGIN, code, err);
    CHECK(code == 1);
    CHECK(strncmp(err, "radiosity: ", 11) == 0 && strstr(err, "--max-memory: ") != NULL);
    CHECK(strchr(err, '\n') == err + strlen(err) - 1);
    CHECK(test_count_files("out") == 0);
    remove_outputs();

    unsigned long long budget = need + MARGIN;
    snprintf(command, sizeof(command), "%s --max-memory %llu --stats stats.json", arguments,
             budget);
    CHECK(run(command) == 0);
    CHECK(test_file_exists(test_path(output)));
    unsigned long long peak = stats_value("memory_budget_peak_bytes");
    unsigned long long resident = stats_value("peak_memory_bytes");
    printf("%-11s needs %.2f MB: budget %.2f MB runs, its high-water mark %.2f MB, peak "
           "resident %.2f MB\n",
           name, need / 1048576.0, budget / 1048576.0, peak / 1048576.0,
           resident / 1048576.0);
    CHECK(peak > 0 && peak <= budget);
    CHECK(resident > 0 && (!RESIDENT_CHECKED || resident <= budget + OVERHEAD));
    remove_outputs();
}

/* GRID x GRID unit cells on the floor (z = 0, facing up) and the ceiling (z = GRID,
 * facing down), each its own surface, as a View3D file (read by the library's own parser,
 * whose allocations the budget sees; Assimp's import of a large OBJ has a transient peak
 * that no check sees, which would belong to the overhead). */
static void write_grid(const char *name)
{
    size_t size = 64 + (size_t)GRID * GRID * 2 * 200;
    char *text = malloc(size);
    CHECK(text != NULL);
    if (!text)
        return;
    size_t length = (size_t)snprintf(text, size, "T grid\nC encl=0\nF 3\n");
    int vertex = 0, surface = 0;
    for (int level = 0; level < 2; level++)
        for (int i = 0; i < GRID; i++)
            for (int j = 0; j < GRID; j++) {
                int z = level ? GRID : 0;
                length += (size_t)snprintf(text + length, size - length,
                                           "V %d %d %d %d\nV %d %d %d %d\nV %d %d %d %d\n"
                                           "V %d %d %d %d\n",
                                           vertex + 1, i, j, z, vertex + 2, i + 1, j, z,
                                           vertex + 3, i + 1, j + 1, z, vertex + 4, i, j + 1,
                                           z);
                surface++;
                if (level)
                    length += (size_t)snprintf(text + length, size - length,
                                               "S %d %d %d %d %d 0 0 0.9 c_%d_%d\n", surface,
                                               vertex + 4, vertex + 3, vertex + 2, vertex + 1,
                                               i, j);
                else
                    length += (size_t)snprintf(text + length, size - length,
                                               "S %d %d %d %d %d 0 0 0.9 f_%d_%d\n", surface,
                                               vertex + 1, vertex + 2, vertex + 3, vertex + 4,
                                               i, j);
                vertex += 4;
            }
    test_write_file(name, text);
    free(text);
}

/* The library's budget in process: an allocation past it fails as out of memory and says
 * how much it asked for; up-front checks and reservations draw on the same budget; no
 * budget, no limit. A W x H image asks for 12 W H bytes at once (rad_image_create). */
static void check_library_budget(void)
{
    rad_error error = {0};
    rad_image *image = NULL;
    char text[256];
    rad_memory_budget_set(0);
    CHECK(rad_memory_budget() == 0 && rad_memory_budget_left() == UINT64_MAX);
    CHECK(!rad_memory_budget_refusal(text, sizeof(text)));
    uint64_t in_use = rad_memory_in_use();
    CHECK(in_use > 0);

    /* 8 MB more than in use: a 1000 x 1000 image (12,000,000 bytes) does not fit */
    rad_memory_budget_set(in_use + (8u << 20));
    CHECK(rad_image_create(1000, 1000, &image, &error) == RAD_ERR_NOMEM);
    CHECK(image == NULL);
    CHECK(rad_memory_budget_refusal(text, sizeof(text)));
    CHECK(strncmp(text, "--max-memory: 11.4 MB more, with ", 33) == 0);
    CHECK(strstr(text, " in use, would exceed the budget of ") != NULL);
    /* a 512 x 512 one (3,145,728 bytes) does, and the high-water mark holds it */
    CHECK(rad_image_create(512, 512, &image, &error) == RAD_OK);
    CHECK(rad_memory_budget_peak() >= in_use + 512 * 512 * 12);
    CHECK(rad_memory_budget_peak() <= rad_memory_budget());
    rad_image_destroy(image);
    image = NULL;

    /* reserved bytes are taken from what is left, exactly, until given back */
    uint64_t left = rad_memory_budget_left();
    rad_memory_budget_reserve(1u << 20);
    CHECK(left - rad_memory_budget_left() == 1u << 20);
    CHECK(rad_memory_budget_need(left, "the test's buffer", &error) == RAD_ERR_NOMEM);
    CHECK(strncmp(error.message, "--max-memory: the test's buffer needs ", 38) == 0);
    CHECK(strstr(error.message, " MB left of the budget of ") != NULL);
    rad_memory_budget_unreserve(1u << 20);
    CHECK(rad_memory_budget_left() == left);
    CHECK(rad_memory_budget_need(left / 2, "half", &error) == RAD_OK);

    /* no budget: the large image again */
    rad_memory_budget_set(0);
    CHECK(rad_image_create(1000, 1000, &image, &error) == RAD_OK);
    rad_image_destroy(image);
}

/* Embree's monitor: T random triangles, budgets from what the copies and the BVH's
 * estimate need (128 T) upward in steps of 16 T. Embree's blocks taken from malloc count
 * twice (the heap and the monitor), so the smaller budgets pass the estimate and are
 * refused by the monitor during the build; every refusal is RAD_ERR_NOMEM with the
 * refusal recorded, nothing leaks (ASan), and a large enough budget builds. */
static void check_embree_monitor(void)
{
    enum { T = 100000 };
    rad_vec3 *positions = malloc(3 * T * sizeof(*positions));
    uint32_t(*triangles)[3] = malloc(T * sizeof(*triangles));
    CHECK(positions && triangles);
    if (!positions || !triangles) {
        free(positions);
        free(triangles);
        return;
    }
    uint64_t state = 12345;
    for (uint32_t k = 0; k < 3 * T; k++) {
        double c[3];
        for (int axis = 0; axis < 3; axis++) {
            state = state * 6364136223846793005ull + 1442695040888963407ull;
            c[axis] = (double)(state >> 11) / 9007199254740992.0;
        }
        positions[k] = (rad_vec3){c[0], c[1], c[2]};
        triangles[k / 3][k % 3] = k;
    }
    rad_error error = {0};
    rad_tracer *tracer = NULL;
    int by_monitor = 0, refused = 0;
    uint64_t base = rad_memory_in_use();
    for (uint64_t extra = 128 * (uint64_t)T; extra < 1024 * (uint64_t)T; extra += 16 * T) {
        rad_memory_budget_set(base + extra);
        rad_status status = rad_tracer_create(RAD_TRACER_EMBREE_FAST, positions, 3 * T,
                                              (const uint32_t(*)[3])triangles, T, &tracer,
                                              &error);
        if (status == RAD_OK)
            break;
        char text[256];
        refused++;
        CHECK(status == RAD_ERR_NOMEM && tracer == NULL);
        CHECK(rad_memory_budget_refusal(text, sizeof(text)));
        by_monitor += strstr(error.message, "Embree error 4 (out of memory) while building "
                                            "the BVH") != NULL;
    }
    printf("Embree monitor: %d budgets refused, %d of them during the build\n", refused,
           by_monitor);
    CHECK(tracer != NULL);
    CHECK(by_monitor > 0);
    rad_tracer_destroy(tracer);
    rad_memory_budget_set(0);
    free(positions);
    free(triangles);
}

int main(void)
{
    test_tmpdir();
    check_library_budget();
    check_embree_monitor();
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

    char arguments[512], prefix[512];
    const char *common =
        "render -o out.pfm --size 16x16 --spp 1 --patch-size 30 --stats stats.json";
    /* gather: the matrix alone fits the budget, not with the scene, mesh and image */
    unsigned long long budget = matrix + (1 << 20);
    snprintf(arguments, sizeof(arguments), "%s --solver gather --max-memory %llu", common,
             budget);
    snprintf(prefix, sizeof(prefix),
             "radiosity: --max-memory: the gather solver's matrix for %llu patches needs %.1f MB "
             "(4 n^2 bytes), more than the ",
             n, matrix / 1048576.0);
    const char *advice = " for the patch inputs, the occluders and the threads: use a larger "
                         "--patch-size, the hierarchical solver or a larger budget\n";
    expect_refused(arguments, prefix, advice);
    char middle[128];
    snprintf(middle, sizeof(middle), " MB left of the budget of %.1f MB after ",
             budget / 1048576.0);
    CHECK(strstr(test_read_text(test_path("stderr.txt")), middle) != NULL);
    /* what was left is less than the matrix and more than nothing */
    double left = atof(test_read_text(test_path("stderr.txt")) + strlen(prefix));
    CHECK(left > 0 && left * 1048576.0 < matrix);

    /* the automatic choice: hierarchical, and why */
    snprintf(arguments, sizeof(arguments), "%s --max-memory %llu", common, budget);
    CHECK(run(arguments) == 0);
    const char *stats = test_read_text(test_path("stats.json"));
    CHECK(strstr(stats, "\"solver\": \"hierarchical\"") != NULL);
    CHECK(strstr(stats, "\"solver_chosen\": true") != NULL);
    char reason[160];
    snprintf(reason, sizeof(reason),
             "\"solver_reason\": \"the %.1f MB matrix would not fit --max-memory (",
             matrix / 1048576.0);
    CHECK(strstr(stats, reason) != NULL);
    CHECK(stats_value("memory_budget_peak_bytes") <= budget);
    remove_outputs();

    /* direct: the LU copy triples the need */
    budget = 2 * matrix;
    snprintf(arguments, sizeof(arguments), "%s --solver direct --max-memory %llu", common,
             budget);
    snprintf(prefix, sizeof(prefix),
             "radiosity: --max-memory: the direct solver's matrix for %llu patches needs %.1f MB "
             "(12 n^2 bytes), more than the ",
             n, 3 * matrix / 1048576.0);
    expect_refused(arguments, prefix, advice);
    snprintf(middle, sizeof(middle), " MB left of the budget of %.1f MB after ",
             budget / 1048576.0);
    CHECK(strstr(test_read_text(test_path("stderr.txt")), middle) != NULL);

    /* the images: 20 bytes a pixel as PNG with automatic exposure, 12 as PFM or with a
     * fixed exposure; refused before the scene is loaded */
    expect_refused("render -o out.png --size 1000x1000 --max-memory 10M",
                   "radiosity: --max-memory: the 1000 x 1000 image needs 19.1 MB, more than "
                   "the ",
                   " MB left of the budget of 10.0 MB\n");
    expect_refused("render -o out.pfm --size 1000x1000 --max-memory 10M",
                   "radiosity: --max-memory: the 1000 x 1000 image needs 11.4 MB, more than "
                   "the ",
                   " MB left of the budget of 10.0 MB\n");
    expect_refused("render -o out.png --exposure 0 --size 1000x1000 --max-memory 10M",
                   "radiosity: --max-memory: the 1000 x 1000 image needs 11.4 MB, more than "
                   "the ",
                   " MB left of the budget of 10.0 MB\n");
    expect_refused("raytrace -o out.png --size 1000x1000 --max-memory 15M",
                   "radiosity: --max-memory: the 1000 x 1000 image needs 19.1 MB, more than "
                   "the ",
                   " MB left of the budget of 15.0 MB\n");
    expect_refused("pathtrace -o out.pfm --standard-error out-error.pfm --size 1000x1000 "
                   "--max-memory 20M",
                   "radiosity: --max-memory: the 1000 x 1000 image with its standard error "
                   "needs 22.9 MB, more than the ",
                   " MB left of the budget of 20.0 MB\n");
    /* a budget reserved for the image holds while the scene loads: the image with room
     * for the built-in scene runs */
    CHECK(run("pathtrace -o out.pfm --size 1000x1000 --spp 1 --max-depth 1 --max-memory 16M") ==
          0);
    remove(test_path("out.pfm"));

    /* viewfactors: the matrix's bound */
    write_grid("grid.vs3");
    unsigned long long pairs = (unsigned long long)GRID * GRID * GRID * GRID;
    unsigned long long surfaces = 2ull * GRID * GRID;
    unsigned long long bound = 24 * pairs + 20 * 2 * pairs + 16 * (surfaces + 1);
    snprintf(prefix, sizeof(prefix),
             "radiosity: --max-memory: the view-factor matrix of %llu surfaces (%llu pairs "
             "that face each other) needs %.1f MB, more than the ",
             surfaces, pairs, bound / 1048576.0);
    expect_refused("viewfactors grid.vs3 -o out.csv --max-memory 3M --sight-rays none", prefix,
                   " MB left of the budget of 3.0 MB\n");
    /* with sight rays (the default), once they have found which pairs see each other: the
     * floor's and the ceiling's cells all do (the smallest factor, corner to far corner,
     * is about 1.6e-4: 30k rays from each side miss such a pair with probability 6e-5) */
    snprintf(prefix, sizeof(prefix),
             "radiosity: --max-memory: the view-factor matrix of %llu surfaces (%llu pairs "
             "that some sight ray found in sight of each other) needs %.1f MB, more than the ",
             surfaces, pairs, bound / 1048576.0);
    expect_refused("viewfactors grid.vs3 -o out.csv --max-memory 3M", prefix,
                   " MB left of the budget of 3.0 MB\n");

    /* the light at the vertices, which follows the solve, must fit before anything is
     * solved: VERTEX_LIGHT_BYTES_PER_PATCH (864) bytes a patch */
    snprintf(arguments, sizeof(arguments), "%s --solver hierarchical --max-memory 2M", common);
    snprintf(prefix, sizeof(prefix),
             "radiosity: --max-memory: the light at the vertices after the solve (none with "
             "--direct solution) needs %.1f MB, more than the ",
             864.0 * n / 1048576.0);
    expect_refused(arguments, prefix, " left of the budget of 2.0 MB\n");
    /* the same for solve's lit mesh */
    expect_refused("solve -o out.ply --patch-size 30 --solver hierarchical --max-memory 2M",
                   prefix, " left of the budget of 2.0 MB\n");
    /* hierarchical: the trees and the solver's per-thread buffers come first */
    snprintf(arguments, sizeof(arguments),
             "%s --solver hierarchical --direct solution --max-memory 2M", common);
    snprintf(prefix, sizeof(prefix),
             "radiosity: --max-memory: the element and cluster trees of %llu patches and the "
             "solver's per-thread buffers need up to ",
             n);
    expect_refused(arguments, prefix, " MB left of the budget of 2.0 MB\n");
    /* and then its links stop where the budget is, saying so, within it */
    snprintf(arguments, sizeof(arguments), "%s --solver hierarchical --max-memory 8M", common);
    CHECK(run(arguments) == 0);
    CHECK(strstr(test_read_text(test_path("stderr.txt")), "--max-memory: the links reached") !=
          NULL);
    CHECK(strstr(test_read_text(test_path("stats.json")), "\"memory_capped\": true") != NULL);
    CHECK(stats_value("memory_budget_peak_bytes") <= 8ull << 20);
    CHECK(!RESIDENT_CHECKED || stats_value("peak_memory_bytes") <= (8ull << 20) + OVERHEAD);
    remove_outputs();

    /* every command: refused just below its need, runs just above, within the budget */
    check_command("render",
                  "render -o out.pfm --size 64x64 --spp 1 --patch-size 45 --solver gather "
                  "--threads 1",
                  "out.pfm");
    check_command("solve", "solve -o out.ply --patch-size 45 --solver gather --threads 1",
                  "out.ply");
    check_command("viewfactors", "viewfactors grid.vs3 -o out.csv --threads 1", "out.csv");
    check_command("pathtrace", "pathtrace -o out.pfm --size 64x64 --spp 4 --threads 1",
                  "out.pfm");
    check_command("raytrace", "raytrace -o out.pfm --size 64x64 --threads 1", "out.pfm");
    check_command("illuminance",
                  "illuminance --plane 100 -o out.csv --patch-size 45 --solver gather "
                  "--threads 1",
                  "out.csv");
    return test_finish("test_memory_budget");
}
