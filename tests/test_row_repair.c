/*
 * test_row_repair.c - the row repair that trims rows above 1 keeping reciprocity
 * (rad_viewfactor_matrix_repair_rows, `viewfactors --repair-rows`): a hand-worked case
 * (one row at 1.2: its scale is 1/1.2, the changes and the removed share by hand), random
 * matrices with curved surfaces (reciprocity within 1e-9 after, every row at most 1, a row
 * whose factors all shrank sums to 1, no factor grows, the report equal to the changes the
 * test measures), the limits (refused, matrix untouched), an unpaired factor refused; and
 * through the command line on a sampled scene whose rows exceed 1: the printed figures
 * equal what the test measures between the runs without and with the repair, refusal past
 * --repair-max-change with exit 1 and no file, usage errors.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/random.h"
#include "testlib.h"

/* A matrix from a dense n x n array of factors (zeros not stored). */
static rad_viewfactor_matrix *from_dense(uint32_t n, const double *area, const double *F)
{
    uint64_t nonzeros = 0;
    for (uint32_t k = 0; k < n * n; k++)
        nonzeros += F[k] != 0;
    rad_viewfactor_matrix *m = NULL;
    rad_error error = {0};
    if (rad_viewfactor_matrix_create(n, nonzeros, &m, &error) != RAD_OK) {
        fprintf(stderr, "%s\n", error.message);
        exit(1);
    }
    uint64_t at = 0;
    for (uint32_t I = 0; I < n; I++) {
        m->area[I] = area[I];
        m->row_start[I] = at;
        for (uint32_t J = 0; J < n; J++)
            if (F[I * n + J] != 0) {
                m->column[at] = J;
                m->value[at] = F[I * n + J];
                m->error_bound[at++] = 1e-3;
            }
    }
    m->row_start[n] = at;
    return m;
}

/* What the repair changed, measured between `before` and `after` (same pattern). */
typedef struct measured {
    double largest_change, largest_relative_change, removed_share, reciprocity, largest_row;
    bool grew;
} measured;

static measured measure(const rad_viewfactor_matrix *before, const rad_viewfactor_matrix *after)
{
    measured r = {0};
    double exchange = 0, removed = 0;
    for (uint32_t I = 0; I < after->n; I++) {
        double sum = 0;
        for (uint64_t k = after->row_start[I]; k < after->row_start[I + 1]; k++) {
            double change = fabs(after->value[k] - before->value[k]);
            r.largest_change = fmax(r.largest_change, change);
            r.largest_relative_change = fmax(r.largest_relative_change, change / before->value[k]);
            r.grew = r.grew || after->value[k] > before->value[k] * (1 + 1e-15);
            exchange += after->area[I] * before->value[k];
            removed += after->area[I] * (before->value[k] - after->value[k]);
            sum += after->value[k];
            uint32_t J = after->column[k];
            double a = after->area[I] * after->value[k];
            double b = after->area[J] * rad_viewfactor_matrix_get(after, J, I);
            r.reciprocity = fmax(r.reciprocity, fabs(a - b) / fmax(a, b));
        }
        r.largest_row = fmax(r.largest_row, sum);
    }
    r.removed_share = removed / exchange;
    return r;
}

static rad_viewfactor_matrix *copy_of(const rad_viewfactor_matrix *m)
{
    rad_viewfactor_matrix *c = NULL;
    rad_error error = {0};
    if (rad_viewfactor_matrix_create(m->n, m->row_start[m->n], &c, &error) != RAD_OK)
        exit(1);
    memcpy(c->area, m->area, m->n * sizeof(double));
    memcpy(c->row_start, m->row_start, (m->n + 1) * sizeof(uint64_t));
    memcpy(c->column, m->column, m->row_start[m->n] * sizeof(uint32_t));
    memcpy(c->value, m->value, m->row_start[m->n] * sizeof(double));
    memcpy(c->error_bound, m->error_bound, m->row_start[m->n] * sizeof(double));
    return c;
}

/* A_1 = 1 with F_12 = F_13 = 0.6 (row 1.2), A_2 = A_3 = 2 with F_21 = F_31 = 0.3 and F_23
 * = F_32 = 0.2 (rows 0.5). Row 1 alone is over, so s_1 = 1/1.2, s_2 = s_3 = 1: F'_12 =
 * 0.5, F'_21 = 0.25, the exchange sum A F = 3.2 loses 2 x 1.2 x (1 - 1/1.2) = 0.4. */
static void check_hand_worked(void)
{
    const double area[3] = {1, 2, 2};
    const double F[9] = {0, 0.6, 0.6, 0.3, 0, 0.2, 0.3, 0.2, 0};
    rad_viewfactor_matrix *m = from_dense(3, area, F);
    rad_viewfactor_matrix *before = copy_of(m);
    rad_row_repair_report report;
    rad_error error = {0};
    CHECK(rad_viewfactor_matrix_repair_rows(m, NULL, NULL, &report, &error) == RAD_OK);
    CHECK_NEAR(rad_viewfactor_matrix_get(m, 0, 1), 0.5, 1e-14);
    CHECK_NEAR(rad_viewfactor_matrix_get(m, 0, 2), 0.5, 1e-14);
    CHECK_NEAR(rad_viewfactor_matrix_get(m, 1, 0), 0.25, 1e-14);
    CHECK_NEAR(rad_viewfactor_matrix_get(m, 2, 0), 0.25, 1e-14);
    CHECK_NEAR(rad_viewfactor_matrix_get(m, 1, 2), 0.2, 1e-14);
    CHECK(report.rows_above_one == 1 && report.rows_trimmed == 1);
    CHECK_NEAR(report.largest_row_sum_before, 1.2, 1e-14);
    CHECK_NEAR(report.largest_row_sum_after, 1, 1e-14);
    CHECK_NEAR(report.largest_change, 0.1, 1e-12);
    CHECK(report.largest_change_row == 0 && report.largest_change_column == 1);
    CHECK_NEAR(report.largest_change_before, 0.6, 1e-14);
    CHECK_NEAR(report.largest_change_after, 0.5, 1e-14);
    CHECK_NEAR(report.largest_relative_change, 1.0 / 6, 1e-12);
    CHECK(report.largest_relative_row == 0 && report.largest_relative_column == 1);
    CHECK_NEAR(report.removed_share, 0.4 / 3.2, 1e-12);
    CHECK(report.reciprocity_after <= 1e-15);
    measured r = measure(before, m);
    CHECK_NEAR(r.removed_share, report.removed_share, 1e-12);
    printf("hand-worked: F'_12 %.15f, removed %.15f (0.125), %u sweeps\n",
           rad_viewfactor_matrix_get(m, 0, 1), report.removed_share, report.sweeps);

    /* limits: refused, untouched */
    rad_viewfactor_matrix *fresh = from_dense(3, area, F);
    rad_row_repair_limits change = {0.1, 0};
    CHECK(rad_viewfactor_matrix_repair_rows(fresh, NULL, &change, &report, &error) ==
          RAD_ERR_INVALID);
    CHECK(report.refused == RAD_ROW_REPAIR_REFUSED_CHANGE);
    CHECK(strstr(error.message, "refused") != NULL);
    CHECK(memcmp(fresh->value, before->value, 6 * sizeof(double)) == 0);
    rad_row_repair_limits removed = {0.2, 0.1};
    CHECK(rad_viewfactor_matrix_repair_rows(fresh, NULL, &removed, &report, &error) ==
          RAD_ERR_INVALID);
    CHECK(report.refused == RAD_ROW_REPAIR_REFUSED_REMOVED);
    CHECK(memcmp(fresh->value, before->value, 6 * sizeof(double)) == 0);
    rad_row_repair_limits enough = {0.2, 0.13};
    CHECK(rad_viewfactor_matrix_repair_rows(fresh, NULL, &enough, &report, &error) == RAD_OK);

    /* F_12 stored without F_21 */
    const double unpaired[9] = {0, 0.6, 0.6, 0, 0, 0.2, 0.3, 0.2, 0};
    rad_viewfactor_matrix *bad = from_dense(3, area, unpaired);
    CHECK(rad_viewfactor_matrix_repair_rows(bad, NULL, NULL, &report, &error) ==
          RAD_ERR_INVALID);
    CHECK(strstr(error.message, "reciprocal") != NULL);
    rad_viewfactor_matrix_destroy(bad);
    rad_viewfactor_matrix_destroy(fresh);
    rad_viewfactor_matrix_destroy(before);
    rad_viewfactor_matrix_destroy(m);
}

/* Random symmetric transfers (a third of the pairs, every fifth surface curved, seeing
 * itself), scaled so that rows range about 0.6 to 1.3. */
static void check_random(uint64_t seed, uint32_t n)
{
    rad_rng rng = rad_rng_seed(seed, 3, 5);
    double *area = calloc(n, sizeof(double)), *G = calloc((size_t)n * n, sizeof(double));
    double *F = calloc((size_t)n * n, sizeof(double));
    for (uint32_t I = 0; I < n; I++)
        area[I] = 0.5 + 2 * rad_rng_uniform(&rng);
    for (uint32_t I = 0; I < n; I++)
        for (uint32_t J = I; J < n; J++)
            if ((J == I && I % 5 == 0) || (J != I && rad_rng_uniform(&rng) < 0.33))
                G[I * n + J] = G[J * n + I] = rad_rng_uniform(&rng) * fmin(area[I], area[J]);
    for (uint32_t k = 0; k < n * n; k++)
        F[k] = G[k] / area[k / n];
    /* bring the rows near the targets by one symmetric scaling pass, so some exceed 1 */
    double *scale = calloc(n, sizeof(double));
    for (uint32_t I = 0; I < n; I++) {
        double sum = 0;
        for (uint32_t J = 0; J < n; J++)
            sum += F[I * n + J];
        scale[I] = sum > 0 ? sqrt((0.6 + 0.7 * rad_rng_uniform(&rng)) / sum) : 1;
    }
    for (uint32_t I = 0; I < n; I++)
        for (uint32_t J = 0; J < n; J++)
            F[I * n + J] = scale[I] * scale[J] * G[I * n + J] / area[I];
    rad_viewfactor_matrix *m = from_dense(n, area, F);
    rad_viewfactor_matrix *before = copy_of(m);
    uint32_t over = 0;
    for (uint32_t I = 0; I < n; I++) {
        double sum = 0;
        for (uint32_t J = 0; J < n; J++)
            sum += F[I * n + J];
        over += sum > 1;
    }
    rad_row_repair_report report;
    rad_error error = {0};
    CHECK(rad_viewfactor_matrix_repair_rows(m, NULL, NULL, &report, &error) == RAD_OK);
    measured r = measure(before, m);
    printf("random %u surfaces (%u rows above 1): largest change %.4g (relative %.4g), removed "
           "%.4g, reciprocity %.2g, largest row %.15f, %u sweeps\n",
           n, over, report.largest_change, report.largest_relative_change, report.removed_share,
           report.reciprocity_after, r.largest_row, report.sweeps);
    CHECK(over > 0);
    CHECK(report.rows_above_one == over);
    CHECK(r.reciprocity <= 1e-9);
    CHECK(r.largest_row <= 1 + 1e-12);
    CHECK(!r.grew);
    CHECK_NEAR(report.largest_change, r.largest_change, 1e-12);
    CHECK_NEAR(report.largest_relative_change, r.largest_relative_change, 1e-12);
    CHECK_NEAR(report.removed_share, r.removed_share, 1e-10);
    CHECK(report.reciprocity_after <= r.reciprocity + 1e-16);
    CHECK_NEAR(report.largest_row_sum_after, r.largest_row, 1e-14);
    /* the fixed point: a row whose every factor shrank has its scale below 1, so it sums
     * to 1; the others kept scale 1 and are at most 1 */
    for (uint32_t I = 0; I < n; I++) {
        bool all_shrank = m->row_start[I + 1] > m->row_start[I];
        double sum = 0;
        for (uint64_t k = m->row_start[I]; k < m->row_start[I + 1]; k++) {
            all_shrank = all_shrank && m->value[k] < before->value[k] * (1 - 1e-13);
            sum += m->value[k];
        }
        if (all_shrank)
            CHECK_NEAR(sum, 1, 1e-12);
    }
    rad_viewfactor_matrix_destroy(before);
    rad_viewfactor_matrix_destroy(m);
    free(scale);
    free(F);
    free(G);
    free(area);
}

/* --- the command line ------------------------------------------------------------- */

typedef struct mtx {
    uint32_t n;
    double area[16];
    double F[16][16];
} mtx;

static bool read_mtx(const char *path, mtx *m)
{
    memset(m, 0, sizeof(*m));
    FILE *f = fopen(path, "r");
    if (!f)
        return false;
    char line[512];
    bool size_seen = false;
    while (fgets(line, sizeof(line), f)) {
        unsigned k, rows, cols;
        double area, value;
        unsigned long long nonzeros;
        if (sscanf(line, "%% surface %u %lf", &k, &area) == 2 && k >= 1 && k <= 16)
            m->area[k - 1] = area;
        else if (line[0] == '%')
            continue;
        else if (!size_seen && sscanf(line, "%u %u %llu", &rows, &cols, &nonzeros) == 3) {
            m->n = rows;
            size_seen = true;
        } else if (size_seen && sscanf(line, "%u %u %lf", &rows, &cols, &value) == 3 &&
                   rows >= 1 && rows <= 16 && cols >= 1 && cols <= 16)
            m->F[rows - 1][cols - 1] = value;
    }
    fclose(f);
    return size_seen && m->n <= 16;
}

static double stats_value(const char *path, const char *key)
{
    const char *json = test_read_text(path);
    char pattern[128];
    snprintf(pattern, sizeof(pattern), "\"%s\":", key);
    const char *at = strstr(json, pattern);
    return at ? strtod(at + strlen(pattern), NULL) : NAN;
}

/* The unit cube (inward) with a 0.5 x 0.5 blocker split 4 x 4 halfway up: the pairs seen
 * past it are sampled, and with few rays some rows come out above 1. */
static void write_noisy_box(void)
{
    static char obj[1 << 14];
    size_t n = (size_t)snprintf(obj, sizeof(obj),
                                "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\n"
                                "v 0 1 1\no bottom\nf 1 2 3 4\no top\nf 5 8 7 6\no front\n"
                                "f 1 5 6 2\no back\nf 4 3 7 8\no left\nf 1 4 8 5\no right\n"
                                "f 2 6 7 3\no blocker\n");
    int v = 8;
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++) {
            double x0 = 0.25 + 0.125 * i, x1 = x0 + 0.125, y0 = 0.25 + 0.125 * j, y1 = y0 + 0.125;
            n += (size_t)snprintf(obj + n, sizeof(obj) - n,
                                  "v %g %g 0.5\nv %g %g 0.5\nv %g %g 0.5\nv %g %g 0.5\n"
                                  "f %d %d %d %d\n",
                                  x0, y0, x0, y1, x1, y1, x1, y0, v + 1, v + 2, v + 3, v + 4);
            v += 4;
        }
    test_write_file("noisy.obj", obj);
}

static void check_command_line(void)
{
    write_noisy_box();
    /* the first seed whose sampled rows exceed 1 (a row sum prints as 1.00xxxx) */
    int seed = 0;
    mtx before, after;
    char command[512];
    for (int s = 1; s <= 40 && !seed; s++) {
        snprintf(command, sizeof(command),
                 "viewfactors noisy.obj -o before.mtx --max-rays 64 --exact-occluders 4 "
                 "--seed %d",
                 s);
        if (test_run_tool(command) != 0 || !read_mtx(test_path("before.mtx"), &before))
            break;
        for (uint32_t I = 0; I < before.n; I++) {
            double sum = 0;
            for (uint32_t J = 0; J < before.n; J++)
                sum += before.F[I][J];
            if (sum > 1 + 1e-6)
                seed = s;
        }
    }
    /* if the engine ever stops sampling these pairs, this scene needs another source of
     * rows above 1 */
    CHECK(seed > 0);
    if (!seed)
        return;
    snprintf(command, sizeof(command),
             "viewfactors noisy.obj -o after.mtx --max-rays 64 --exact-occluders 4 "
             "--seed %d --repair-rows "
             "--stats repair.json",
             seed);
    CHECK(test_run_tool(command) == 0);
    CHECK(read_mtx(test_path("after.mtx"), &after) && after.n == before.n);
    CHECK(strstr(test_read_text(test_path("stderr.txt")), "row repair: ") != NULL);
    double largest = 0, relative = 0, exchange = 0, removed = 0, reciprocity = 0, row = 0;
    for (uint32_t I = 0; I < after.n; I++) {
        double sum = 0;
        for (uint32_t J = 0; J < after.n; J++) {
            double a = before.F[I][J], b = after.F[I][J];
            if (a == 0)
                continue;
            largest = fmax(largest, fabs(a - b));
            relative = fmax(relative, fabs(a - b) / a);
            exchange += before.area[I] * a;
            removed += before.area[I] * (a - b);
            sum += b;
            double x = after.area[I] * b, y = after.area[J] * after.F[J][I];
            reciprocity = fmax(reciprocity, fabs(x - y) / fmax(x, y));
        }
        row = fmax(row, sum);
    }
    const char *stats = test_path("repair.json");
    printf("command line (seed %d): largest change %.6g (printed %.6g), removed %.6g (printed "
           "%.6g), reciprocity %.2g, largest row %.15f\n",
           seed, largest, stats_value(stats, "repair_largest_change"), removed / exchange,
           stats_value(stats, "repair_removed_share"), reciprocity, row);
    CHECK(largest > 0);
    CHECK_NEAR(stats_value(stats, "repair_largest_change"), largest, 1e-8);
    CHECK_NEAR(stats_value(stats, "repair_largest_relative_change"), relative, 1e-8);
    CHECK_NEAR(stats_value(stats, "repair_removed_share"), removed / exchange, 1e-6);
    CHECK(reciprocity <= 1e-9);
    CHECK(row <= 1 + 1e-12);

    /* past the limit: exit 1, a message naming the option, no file */
    snprintf(command, sizeof(command),
             "viewfactors noisy.obj -o refused.mtx --max-rays 64 --exact-occluders 4 "
             "--seed %d --repair-rows "
             "--repair-max-change %.6g",
             seed, 0.5 * relative);
    CHECK(test_run_tool(command) == 1);
    CHECK(strstr(test_read_text(test_path("stderr.txt")), "--repair-max-change") != NULL);
    CHECK(!test_file_exists(test_path("refused.mtx")));
    snprintf(command, sizeof(command),
             "viewfactors noisy.obj -o refused.mtx --max-rays 64 --exact-occluders 4 "
             "--seed %d --repair-rows "
             "--repair-max-removed %.6g",
             seed, 0.5 * removed / exchange);
    CHECK(test_run_tool(command) == 1);
    CHECK(strstr(test_read_text(test_path("stderr.txt")), "--repair-max-removed") != NULL);
    CHECK(!test_file_exists(test_path("refused.mtx")));
    /* usage errors */
    CHECK(test_run_tool("viewfactors noisy.obj -o refused.mtx --repair-max-change 0.1") == 2);
    CHECK(test_run_tool("viewfactors noisy.obj -o refused.mtx --repair-rows --enclosure") == 2);
    CHECK(test_run_tool("viewfactors noisy.obj -o refused.mtx --repair-rows "
                        "--repair-max-change 0") == 2);
    CHECK(!test_file_exists(test_path("refused.mtx")));
}

int main(void)
{
    test_tmpdir();
    check_hand_worked();
    check_random(1, 40);
    check_random(2, 200);
    check_command_line();
    return test_finish("test_row_repair");
}
