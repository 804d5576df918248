/*
 * test_enclosure_errors.c - every way rad_viewfactor_matrix_close_enclosure (viewfactors
 * --enclosure) refuses a matrix, one case each, and that each message names the scene's
 * file first (the user's handle on what to fix): a matrix of another size than the scene,
 * a surface of zero or infinite area, a factor that is NaN or negative, a factor stored
 * without its reciprocal, an empty row, a singular system (two facing plates), and a
 * correction that would turn a factor negative. Through the tool: the singular case, one
 * line (the last, after the summary of the computed factors), exit 1, no output file.
 * (Out of memory is the one failure not provoked here.)
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "testlib.h"

/* Four unit squares a, b, c, d (the matrices below give their areas and factors). */
static const char squares_vs3[] =
    "F 3\n"
    "V 1 0 0 0\nV 2 1 0 0\nV 3 1 1 0\nV 4 0 1 0\n"
    "V 5 0 0 1\nV 6 1 0 1\nV 7 1 1 1\nV 8 0 1 1\n"
    "V 9 2 0 0\nV 10 3 0 0\nV 11 3 1 0\nV 12 2 1 0\n"
    "V 13 2 0 1\nV 14 3 0 1\nV 15 3 1 1\nV 16 2 1 1\n"
    "S 1 1 2 3 4 0 0 0.9 a\nS 2 5 8 7 6 0 0 0.9 b\n"
    "S 3 9 10 11 12 0 0 0.9 c\nS 4 13 16 15 14 0 0 0.9 d\n";

/* A matrix of n surfaces from a dense table (0 = not stored). */
static rad_viewfactor_matrix *dense(uint32_t n, const double *area, const double *F)
{
    uint64_t nonzeros = 0;
    for (uint32_t k = 0; k < n * n; k++)
        nonzeros += F[k] != 0;
    rad_viewfactor_matrix *m = NULL;
    rad_error error = {0};
    if (rad_viewfactor_matrix_create(n, nonzeros, &m, &error) != RAD_OK)
        return NULL;
    uint64_t e = 0;
    for (uint32_t I = 0; I < n; I++) {
        m->area[I] = area[I];
        m->row_start[I] = e;
        for (uint32_t J = 0; J < n; J++)
            if (F[I * n + J] != 0) {
                m->column[e] = J;
                m->value[e++] = F[I * n + J];
            }
    }
    m->row_start[n] = e;
    return m;
}

/* The correction of (area, F) over the four squares fails with "PATH: " + words. */
static void expect_failure(const char *case_name, const rad_scene *scene, uint32_t n,
                           const double *area, const double *F, const char *words)
{
    rad_viewfactor_matrix *m = dense(n, area, F);
    CHECK(m != NULL);
    if (!m)
        return;
    rad_error error = {0};
    rad_status status = rad_viewfactor_matrix_close_enclosure(m, scene, NULL, &error);
    char expected[1024];
    snprintf(expected, sizeof(expected), "%s: %s", scene->source, words);
    CHECK(status == RAD_ERR_INVALID);
    if (strcmp(error.message, expected) != 0)
        test_fail(__FILE__, __LINE__, "[%s] expected '%s', got '%s'", case_name, expected,
                  error.message);
    rad_viewfactor_matrix_destroy(m);
}

int main(void)
{
    test_tmpdir();
    rad_scene *scene = NULL;
    rad_error error = {0};
    CHECK(rad_scene_load_vs3(test_write_file("squares.vs3", squares_vs3), NULL, &scene, NULL,
                             &error) == RAD_OK);
    if (!scene)
        return test_finish("test_enclosure_errors");
    CHECK(strcmp(scene->source, test_path("squares.vs3")) == 0);

    /* a closed 4-surface enclosure to start from: everyone sees everyone else by 1/3 */
    const double ones[4] = {1, 1, 1, 1};
    double F[16];
    for (int k = 0; k < 16; k++)
        F[k] = k / 4 == k % 4 ? 0 : 1.0 / 3;
    rad_viewfactor_matrix *good = dense(4, ones, F);
    CHECK(good && rad_viewfactor_matrix_close_enclosure(good, scene, NULL, &error) == RAD_OK);
    rad_viewfactor_matrix_destroy(good);

    expect_failure("size", scene, 3, ones, F,
                   "the enclosure correction: the matrix has 3 surfaces, the scene 4");
    const double zero_area[4] = {1, 0, 1, 1}, infinite_area[4] = {1, 1, INFINITY, 1};
    expect_failure("zero area", scene, 4, zero_area, F,
                   "the enclosure correction: surface 'b' has area 0");
    expect_failure("infinite area", scene, 4, infinite_area, F,
                   "the enclosure correction: surface 'c' has area inf");
    double bad[16];
    memcpy(bad, F, sizeof(bad));
    bad[1 * 4 + 2] = NAN;
    expect_failure("NaN", scene, 4, ones, bad,
                   "the enclosure correction: F from surface 'b' to surface 3 is nan, not a "
                   "view factor");
    memcpy(bad, F, sizeof(bad));
    bad[3 * 4 + 0] = -0.25;
    expect_failure("negative", scene, 4, ones, bad,
                   "the enclosure correction: F from surface 'd' to surface 1 is -0.25, not a "
                   "view factor");
    memcpy(bad, F, sizeof(bad));
    bad[2 * 4 + 1] = 0; /* F_cb gone, F_bc kept */
    expect_failure("no reciprocal", scene, 4, ones, bad,
                   "the enclosure correction: F from surface 'b' to surface 3 is stored "
                   "without its reciprocal");
    memcpy(bad, F, sizeof(bad));
    for (int k = 0; k < 4; k++)
        bad[3 * 4 + k] = bad[k * 4 + 3] = 0; /* d sees nothing, nothing sees d */
    expect_failure("empty row", scene, 4, ones, bad,
                   "the enclosure correction: surface 'd' sees nothing (an empty row): it "
                   "cannot be part of a closed enclosure");
    /* a and b see only each other, c and d only each other: two pairs of facing plates */
    const double pairs[16] = {0, 0.9, 0, 0, 0.9, 0, 0, 0, 0, 0, 0, 0.8, 0, 0, 0.8, 0};
    expect_failure("singular", scene, 4, ones, pairs,
                   "the enclosure correction is singular: surface 'a' and the surfaces it sees "
                   "split into two sets that see only each other");
    /* far from closed: areas (0.1, 0.1, 0.1, 1), transfers A_I F_IJ of 5 between a and c
     * and a and d, 1 between c and d, 0.001 from b to c and d; the least-squares change
     * (worked out separately, 4 x 4 system) takes G_ac to -0.4 */
    const double far_area[4] = {0.1, 0.1, 0.1, 1};
    const double far[16] = {0, 0, 50, 50, 0, 0, 0.01, 0.01, 50, 0.01, 0, 10, 5, 0.001, 1, 0};
    expect_failure("turns negative", scene, 4, far_area, far,
                   "the enclosure correction would make the view factor from surface 'a' to "
                   "surface 'c' negative: the matrix is too far from closed (largest row-sum "
                   "deviation 99)");

    /* through the tool: two facing plates and nothing else, one line naming the file */
    test_write_file("plates.vs3", "F 3\nV 1 0 0 0\nV 2 1 0 0\nV 3 1 1 0\nV 4 0 1 0\n"
                                  "V 5 0 0 1\nV 6 1 0 1\nV 7 1 1 1\nV 8 0 1 1\n"
                                  "S 1 1 2 3 4 0 0 0.9 floor\nS 2 5 8 7 6 0 0 0.9 ceiling\n");
    int code = test_run_tool("viewfactors plates.vs3 --enclosure -o out.csv");
    const char *err = test_read_text(test_path("stderr.txt"));
    /* the summary of the computed factors comes first; the error is the last line */
    const char *last = err + strlen(err);
    while (last > err && last[-1] == '\n')
        last--;
    while (last > err && last[-1] != '\n')
        last--;
    CHECK(code == 1);
    CHECK(strcmp(last, "radiosity: plates.vs3: the enclosure correction is singular: surface "
                       "'floor' and the surfaces it sees split into two sets that see only "
                       "each other\n") == 0);
    CHECK(!test_file_exists(test_path("out.csv")));
    if (code != 1 || !strstr(err, "radiosity: plates.vs3: the enclosure"))
        fprintf(stderr, "stderr: %s\n", err);
    rad_scene_destroy(scene);
    return test_finish("test_enclosure_errors");
}
