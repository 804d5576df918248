/*
 * test_vfmatrix.c - post-processing and writing of surface view-factor matrices built by
 * hand from closed forms (shared/docs/VALIDATION.md): the unit cube (opposite faces from
 * the parallel-rectangles formula, adjacent from the perpendicular one) and concentric
 * spheres (F_21 = (r1/r2)^2, F_22 = 1 - F_21). The enclosure correction must close
 * perturbed rows with reciprocity exact and leave a consistent matrix alone; script-F
 * must meet reciprocity, row sums eps_I and the two-surface closed form; the writers'
 * files are parsed back.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "closed_forms.h"
#include "testlib.h"

/* the unit squares' closed forms (Howell's catalogue, tests/closed_forms.h) */
static double parallel_squares(void) { return parallel_rectangles(1, 1, 1); }
static double perpendicular_squares(void) { return perpendicular_rectangles(1, 1, 1); }

/* A dense row-major matrix as CSR (zeros not stored). */
static rad_viewfactor_matrix *from_dense(uint32_t n, const double *F, const double *area)
{
    uint64_t nz = 0;
    for (uint32_t i = 0; i < n * n; i++)
        nz += F[i] != 0;
    rad_viewfactor_matrix *m = NULL;
    rad_error error;
    if (rad_viewfactor_matrix_create(n, nz, &m, &error) != RAD_OK) {
        fprintf(stderr, "%s\n", error.message);
        exit(1);
    }
    uint64_t k = 0;
    for (uint32_t I = 0; I < n; I++) {
        m->area[I] = area[I];
        m->row_start[I] = k;
        for (uint32_t J = 0; J < n; J++)
            if (F[I * n + J] != 0) {
                m->column[k] = J;
                m->value[k] = F[I * n + J];
                m->error_bound[k] = 1e-6;
                k++;
            }
    }
    m->row_start[n] = k;
    return m;
}

/* The unit cube in View3D's surface order zeq0 xeq0 yeq0 zeq1 xeq1 yeq1: I and I+3 are
 * opposite. With `exact` the adjacent factor is (1 - F_opposite) / 4, so rows sum to 1. */
static void cube_matrix(double *F, bool exact)
{
    double opposite = parallel_squares();
    double adjacent = exact ? (1 - opposite) / 4 : perpendicular_squares();
    for (int I = 0; I < 6; I++)
        for (int J = 0; J < 6; J++)
            F[I * 6 + J] = I == J ? 0 : (I % 3 == J % 3 ? opposite : adjacent);
}

/* A deterministic pseudo-random number in [-1, 1]. */
static double wobble(uint32_t k)
{
    uint32_t x = k * 2654435761u + 12345u;
    x ^= x >> 15;
    x *= 2246822519u;
    x ^= x >> 13;
    return (double)(x % 20001) / 10000.0 - 1.0;
}

static void check_closed(const rad_viewfactor_matrix *m, double tolerance)
{
    for (uint32_t I = 0; I < m->n; I++) {
        double row = 0;
        for (uint64_t k = m->row_start[I]; k < m->row_start[I + 1]; k++) {
            uint32_t J = m->column[k];
            row += m->value[k];
            double a = m->area[I] * m->value[k], b = m->area[J] * rad_viewfactor_matrix_get(m, J, I);
            CHECK_ABS(a - b, 0, tolerance * fmax(a, b));
        }
        CHECK_ABS(row, 1, tolerance);
    }
}

static void test_closed_forms(void)
{
    /* the values VALIDATION.md and View3D's manual print */
    CHECK_ABS(parallel_squares(), 0.1998249, 5e-8);
    CHECK_ABS(perpendicular_squares(), 0.2000438, 5e-8);
}

static void test_enclosure_cube(void)
{
    double F[36], area[6] = {1, 1, 1, 1, 1, 1};
    rad_error error = {0};
    rad_enclosure_report report;

    /* a consistent matrix is left as it is */
    cube_matrix(F, true);
    rad_viewfactor_matrix *m = from_dense(6, F, area);
    CHECK(rad_viewfactor_matrix_close_enclosure(m, NULL, &report, &error) == RAD_OK);
    CHECK(report.largest_relative_change < 1e-13);
    CHECK(report.row_deviation_before < 1e-15);
    for (uint32_t I = 0; I < 6; I++)
        for (uint32_t J = 0; J < 6; J++)
            CHECK_NEAR(rad_viewfactor_matrix_get(m, I, J), F[I * 6 + J], 1e-14);
    rad_viewfactor_matrix_destroy(m);

    /* the analytic cube: rows sum to 1 within 1e-7 already (4 x 0.2000438 + 0.1998249) */
    cube_matrix(F, false);
    m = from_dense(6, F, area);
    for (uint32_t I = 0; I < 6; I++) {
        double row = 0;
        for (uint32_t J = 0; J < 6; J++) {
            row += rad_viewfactor_matrix_get(m, I, J);
            CHECK(rad_viewfactor_matrix_get(m, I, J) == rad_viewfactor_matrix_get(m, J, I));
        }
        CHECK_ABS(row, 1, 1e-6);
    }
    rad_viewfactor_matrix_destroy(m);

    /* perturbed by up to 2 %, not reciprocal, areas not 1 (a 1 x 1 x 1 cube scaled: the
     * factors do not change, the areas do) */
    for (int k = 0; k < 36; k++)
        F[k] *= 1 + 0.02 * wobble((uint32_t)k);
    for (int I = 0; I < 6; I++)
        area[I] = 4.0;
    m = from_dense(6, F, area);
    double before = 0;
    for (int I = 0; I < 6; I++) {
        double row = 0;
        for (int J = 0; J < 6; J++)
            row += F[I * 6 + J];
        before = fmax(before, fabs(row - 1));
    }
    CHECK(rad_viewfactor_matrix_close_enclosure(m, NULL, &report, &error) == RAD_OK);
    CHECK_NEAR(report.row_deviation_before, before, 1e-12);
    CHECK(report.row_deviation_before > 1e-3);
    CHECK(report.row_deviation_after < 1e-12);
    CHECK(report.reciprocity_after < 1e-12);
    CHECK(report.largest_relative_change > 1e-3 && report.largest_relative_change < 0.1);
    CHECK(report.iterations > 0);
    check_closed(m, 1e-9);
    /* the correction is small: every factor stays within 5 % of the analytic one */
    cube_matrix(F, false);
    for (int I = 0; I < 6; I++)
        for (int J = 0; J < 6; J++)
            CHECK_NEAR(rad_viewfactor_matrix_get(m, (uint32_t)I, (uint32_t)J), F[I * 6 + J], 0.05);
    CHECK(rad_viewfactor_matrix_get(m, 0, 0) == 0); /* zeros stay zero */
    rad_viewfactor_matrix_destroy(m);
}

/* Two concentric spheres (curved surface 2 sees itself): the diagonal is corrected too. */
static void test_enclosure_spheres(void)
{
    double r1 = 1, r2 = 2;
    double area[2] = {4 * pi * r1 * r1, 4 * pi * r2 * r2};
    double F21 = (r1 / r2) * (r1 / r2);
    double F[4] = {0, 1.03, F21 * 0.98, (1 - F21) * 1.01};
    rad_viewfactor_matrix *m = from_dense(2, F, area);
    rad_enclosure_report report;
    rad_error error = {0};
    CHECK(rad_viewfactor_matrix_close_enclosure(m, NULL, &report, &error) == RAD_OK);
    check_closed(m, 1e-9);
    CHECK_NEAR(rad_viewfactor_matrix_get(m, 0, 1), 1.0, 1e-12); /* forced by row 1 */
    CHECK_NEAR(rad_viewfactor_matrix_get(m, 1, 0), F21, 1e-12); /* then by reciprocity */
    CHECK_NEAR(rad_viewfactor_matrix_get(m, 1, 1), 1 - F21, 1e-12);
    rad_viewfactor_matrix_destroy(m);
}

static void test_enclosure_refusals(void)
{
    rad_error error = {0};
    rad_enclosure_report report;
    /* two plates seeing only each other: the system is singular */
    double F[4] = {0, 0.9, 0.9, 0};
    double area[3] = {1, 1, 1};
    rad_viewfactor_matrix *m = from_dense(2, F, area);
    double before = m->value[0];
    CHECK(rad_viewfactor_matrix_close_enclosure(m, NULL, &report, &error) == RAD_ERR_INVALID);
    CHECK(strstr(error.message, "singular") != NULL);
    CHECK(m->value[0] == before);
    rad_viewfactor_matrix_destroy(m);

    /* a surface that sees nothing */
    double G[9] = {0, 1, 0, 1, 0, 0, 0, 0, 0};
    m = from_dense(3, G, area);
    CHECK(rad_viewfactor_matrix_close_enclosure(m, NULL, &report, &error) == RAD_ERR_INVALID);
    CHECK(strstr(error.message, "surface 3 sees nothing") != NULL);
    rad_viewfactor_matrix_destroy(m);
}

static void test_script_f(void)
{
    rad_error error = {0};
    /* concentric spheres: the two-surface closed form */
    double r1 = 1, r2 = 2, eps[2] = {0.3, 0.6};
    double area[2] = {4 * pi * r1 * r1, 4 * pi * r2 * r2};
    double F21 = area[0] / area[1];
    double F[4] = {0, 1, F21, 1 - F21};
    rad_viewfactor_matrix *m = from_dense(2, F, area), *s = NULL;
    CHECK(rad_viewfactor_matrix_script_f(m, eps, &s, &error) == RAD_OK);
    if (s) {
        double expected = 1 / (1 / eps[0] + area[0] / area[1] * (1 / eps[1] - 1));
        CHECK_NEAR(rad_viewfactor_matrix_get(s, 0, 1), expected, 1e-12);
        CHECK_NEAR(area[0] * rad_viewfactor_matrix_get(s, 0, 1),
                   area[1] * rad_viewfactor_matrix_get(s, 1, 0), 1e-12);
        for (uint32_t I = 0; I < 2; I++)
            CHECK_NEAR(rad_viewfactor_matrix_get(s, I, 0) + rad_viewfactor_matrix_get(s, I, 1),
                       eps[I], 1e-12);
        CHECK(rad_viewfactor_matrix_get(s, 0, 0) > 0); /* sphere 1 sees itself by reflection */
    }
    rad_viewfactor_matrix_destroy(s);
    /* black surfaces: script-F is F */
    double black[2] = {1, 1};
    CHECK(rad_viewfactor_matrix_script_f(m, black, &s, &error) == RAD_OK);
    if (s)
        for (uint32_t I = 0; I < 2; I++)
            for (uint32_t J = 0; J < 2; J++)
                CHECK_NEAR(rad_viewfactor_matrix_get(s, I, J), F[I * 2 + J], 1e-14);
    rad_viewfactor_matrix_destroy(s);
    rad_viewfactor_matrix_destroy(m);

    /* the cube with six different emissivities and areas 1 */
    double C[36], ones[6] = {1, 1, 1, 1, 1, 1}, e[6] = {0.1, 0.25, 0.5, 0.75, 0.9, 0.99};
    cube_matrix(C, true);
    m = from_dense(6, C, ones);
    CHECK(rad_viewfactor_matrix_script_f(m, e, &s, &error) == RAD_OK);
    if (s) {
        for (uint32_t I = 0; I < 6; I++) {
            double row = 0;
            for (uint32_t J = 0; J < 6; J++) {
                row += rad_viewfactor_matrix_get(s, I, J);
                CHECK_NEAR(rad_viewfactor_matrix_get(s, I, J), rad_viewfactor_matrix_get(s, J, I),
                           1e-12);
            }
            CHECK_NEAR(row, e[I], 1e-12);
        }
    }
    rad_viewfactor_matrix_destroy(s);
    double bad[6] = {0.1, 0, 0.5, 0.5, 0.5, 0.5};
    CHECK(rad_viewfactor_matrix_script_f(m, bad, &s, &error) == RAD_ERR_INVALID);
    rad_viewfactor_matrix_destroy(m);

    /* too many surfaces for the dense solve */
    CHECK(rad_viewfactor_matrix_create(RAD_SCRIPT_F_MAX_SURFACES + 1, 0, &m, &error) == RAD_OK);
    double *many = calloc(RAD_SCRIPT_F_MAX_SURFACES + 1, sizeof(*many));
    s = NULL;
    CHECK(rad_viewfactor_matrix_script_f(m, many, &s, &error) == RAD_ERR_UNSUPPORTED);
    CHECK(s == NULL);
    free(many);
    rad_viewfactor_matrix_destroy(m);
}

/* A cube scene (View3D's example) plus an obstruction surface, and a matrix for it. */
static rad_scene *cube_scene(void)
{
    const char *text =
        "T cube\nF 3\n"
        "V 1 0 0 0\nV 2 1 0 0\nV 3 1 1 0\nV 4 0 1 0\nV 5 0 0 1\nV 6 1 0 1\nV 7 1 1 1\nV 8 0 1 1\n"
        "V 9 0.4 0.4 0.5\nV 10 0.6 0.4 0.5\nV 11 0.6 0.6 0.5\n"
        "S 1 1 2 3 4 0 0 0.50 zeq0\nS 2 1 4 8 5 0 0 0.50 xeq0\nS 3 1 5 6 2 0 0 0.50 yeq0\n"
        "O 4 9 10 11 0 0 0 0.50 blocker\n"
        "S 5 7 6 5 8 0 0 0.50 zeq1\nS 6 7 3 2 6 0 0 0.60 xeq1\nS 7 7 8 4 3 0 0 0.70 yeq1\n";
    rad_scene *scene = NULL;
    rad_error error = {0};
    if (rad_scene_load_vs3(test_write_file("cube.vs3", text), NULL, &scene, NULL, &error) != RAD_OK) {
        fprintf(stderr, "%s\n", error.message);
        exit(1);
    }
    return scene;
}

static void test_writers(void)
{
    rad_scene *scene = cube_scene();
    CHECK(scene->surface_count == 7 && scene->surfaces[3].flags == RAD_SURFACE_OBSTRUCTION);
    /* 7 x 7 with an empty row and column for the blocker (surface index 3) */
    double C[36], F[49] = {0}, area[7] = {1, 1, 1, 0, 1, 1, 1};
    cube_matrix(C, false);
    int map[6] = {0, 1, 2, 4, 5, 6};
    for (int I = 0; I < 6; I++)
        for (int J = 0; J < 6; J++)
            F[map[I] * 7 + map[J]] = C[I * 6 + J];
    rad_viewfactor_matrix *m = from_dense(7, F, area);
    rad_error error = {0};

    /* CSV: the blocker is left out */
    const char *csv = test_path("out.csv");
    CHECK(rad_viewfactor_matrix_write(scene, m, csv, NULL, &error) == RAD_OK);
    const char *text = test_read_text(csv);
    CHECK(strncmp(text, "surface,zeq0,xeq0,yeq0,zeq1,xeq1,yeq1\nzeq0,0,", 45) == 0);
    CHECK(strstr(text, "blocker") == NULL);
    char expected[256];
    snprintf(expected, sizeof(expected), "\nzeq1,%.9g,%.9g,%.9g,0,", parallel_squares(),
             perpendicular_squares(), perpendicular_squares());
    CHECK(strstr(text, expected) != NULL);
    CHECK(rad_viewfactor_format_for_path("a/b.MTX") == RAD_VIEWFACTOR_MATRIX_MARKET);
    CHECK(rad_viewfactor_format_for_path("a/b.csv") == RAD_VIEWFACTOR_CSV);

    /* Matrix Market: parse it back */
    const char *mtx = test_path("out.mtx");
    rad_viewfactor_write_options options = {RAD_VIEWFACTOR_MATRIX_MARKET, false, false, false};
    CHECK(rad_viewfactor_matrix_write(scene, m, mtx, &options, &error) == RAD_OK);
    FILE *f = fopen(mtx, "r");
    CHECK(f != NULL);
    if (f) {
        char line[512];
        CHECK(fgets(line, sizeof(line), f) &&
              strcmp(line, "%%MatrixMarket matrix coordinate real general\n") == 0);
        int names = 0, rows = 0, columns = 0, entries = 0, read = 0;
        while (fgets(line, sizeof(line), f)) {
            unsigned k;
            double value;
            char name[128];
            if (line[0] == '%') {
                if (sscanf(line, "%% surface %u %lf %127s", &k, &value, name) == 3) {
                    names++;
                    CHECK(k == (unsigned)names && value == 1.0);
                    CHECK(strcmp(name, scene->surfaces[map[k - 1]].name) == 0);
                }
                continue;
            }
            if (!rows) {
                CHECK(sscanf(line, "%d %d %d", &rows, &columns, &entries) == 3);
                continue;
            }
            unsigned i, j;
            CHECK(sscanf(line, "%u %u %lf", &i, &j, &value) == 3);
            CHECK(i >= 1 && i <= 6 && j >= 1 && j <= 6 && i != j);
            if (i >= 1 && i <= 6 && j >= 1 && j <= 6)
                CHECK(value == C[(i - 1) * 6 + (j - 1)]); /* %.17g: bitwise */
            read++;
        }
        fclose(f);
        CHECK(names == 6 && rows == 6 && columns == 6 && entries == 30 && read == 30);
    }

    /* View3D's text layout */
    const char *v3d = test_path("out.txt");
    options = (rad_viewfactor_write_options){RAD_VIEWFACTOR_VIEW3D, true, false, false};
    CHECK(rad_viewfactor_matrix_write(scene, m, v3d, &options, &error) == RAD_OK);
    f = fopen(v3d, "r");
    CHECK(f != NULL);
    if (f) {
        char line[512];
        CHECK(fgets(line, sizeof(line), f) && strlen(line) == 31 &&
              strncmp(line, "View3D 3.3 0 1 0 6 ", 19) == 0);
        CHECK(fgets(line, sizeof(line), f) && strcmp(line, "1 1 1 1 1 1\n") == 0);
        for (int I = 0; I < 6; I++) {
            for (int J = 0; J < 6; J++) {
                double value = -1;
                CHECK(fscanf(f, "%lf", &value) == 1);
                CHECK_ABS(value, C[I * 6 + J], 5e-7);
            }
        }
        CHECK(fgets(line, sizeof(line), f) && strcmp(line, "\n") == 0);
        CHECK(fgets(line, sizeof(line), f) &&
              strcmp(line, "0.500 0.500 0.500 0.500 0.600 0.700\n") == 0);
        fclose(f);
    }

    /* a matrix of another size is refused and leaves no file */
    rad_viewfactor_matrix *small = from_dense(6, C, area);
    CHECK(rad_viewfactor_matrix_write(scene, small, test_path("wrong.csv"), NULL, &error) ==
          RAD_ERR_INVALID);
    CHECK(test_count_files("wrong") == 0);
    rad_viewfactor_matrix_destroy(small);
    rad_viewfactor_matrix_destroy(m);
    rad_scene_destroy(scene);
}

int main(void)
{
    test_closed_forms();
    test_enclosure_cube();
    test_enclosure_spheres();
    test_enclosure_refusals();
    test_script_f();
    test_writers();
    return test_finish("test_vfmatrix");
}
