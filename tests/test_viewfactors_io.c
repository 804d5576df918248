/*
 * test_viewfactors_io.c - `radiosity viewfactors` with View3D input files, several mesh
 * files, --obstruction, --two-sided, --enclosure, --script-f and the output layouts.
 * Each .vs3 shape (quadrilaterals, triangles, obstruction surfaces, combined surfaces,
 * subsurfaces) is written here together with the same geometry as OBJ, and the two
 * matrices must agree within the engine's error bound; values are also held to closed forms
 * (shared/docs/VALIDATION.md) where one exists. Bad .vs3 input: one line naming the file
 * and line, exit code 1, no output file.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "testlib.h"

static const double pi = 3.14159265358979323846;

enum { MAX_SURFACES = 16 };

typedef struct matrix {
    int n;
    char name[MAX_SURFACES][64];
    double area[MAX_SURFACES];
    double F[MAX_SURFACES][MAX_SURFACES];
} matrix;

/* Reads a Matrix Market file written by the tool (names and areas from its comments). */
static bool read_mtx(const char *path, matrix *m)
{
    memset(m, 0, sizeof(*m));
    FILE *f = fopen(path, "r");
    if (!f)
        return false;
    char line[512];
    bool sized = false;
    while (fgets(line, sizeof(line), f)) {
        unsigned k, i, j;
        double value;
        char name[64];
        if (line[0] == '%') {
            if (sscanf(line, "%% surface %u %lf %63s", &k, &value, name) == 3 && k >= 1 &&
                k <= MAX_SURFACES) {
                snprintf(m->name[k - 1], sizeof(m->name[0]), "%s", name);
                m->area[k - 1] = value;
            }
            continue;
        }
        if (!sized) {
            unsigned rows, columns, entries;
            if (sscanf(line, "%u %u %u", &rows, &columns, &entries) != 3 || rows > MAX_SURFACES)
                break;
            m->n = (int)rows;
            sized = true;
            continue;
        }
        if (sscanf(line, "%u %u %lf", &i, &j, &value) == 3 && i >= 1 && j >= 1 &&
            i <= (unsigned)m->n && j <= (unsigned)m->n)
            m->F[i - 1][j - 1] = value;
    }
    fclose(f);
    return sized;
}

static int index_of(const matrix *m, const char *name)
{
    for (int k = 0; k < m->n; k++)
        if (strcmp(m->name[k], name) == 0)
            return k;
    test_fail(__FILE__, __LINE__, "no surface '%s'", name);
    return 0;
}

static double factor(const matrix *m, const char *from, const char *to)
{
    return m->F[index_of(m, from)][index_of(m, to)];
}

/* Runs the tool and reads its .mtx output; false (after a failure) when it did not run. */
static bool run_mtx(const char *arguments, const char *output, matrix *m)
{
    char command[4096];
    snprintf(command, sizeof(command), "viewfactors %s -o %s", arguments, output);
    int code = test_run_tool(command);
    CHECK(code == 0);
    if (code != 0) {
        fprintf(stderr, "%s\n", test_read_text(test_path("stderr.txt")));
        return false;
    }
    bool ok = read_mtx(test_path(output), m);
    CHECK(ok);
    return ok;
}

/* Every factor of a and b (matched by name) agrees within the accuracy asked for. */
static void check_same(const matrix *a, const matrix *b, double relative)
{
    CHECK(a->n == b->n);
    for (int i = 0; i < a->n; i++) {
        int bi = index_of(b, a->name[i]);
        CHECK_NEAR(a->area[i], b->area[bi], 1e-12);
        for (int j = 0; j < a->n; j++) {
            double x = a->F[i][j], y = b->F[bi][index_of(b, a->name[j])];
            if (fabs(x - y) > relative * fmax(fabs(x), fabs(y)) + 1e-12)
                test_fail(__FILE__, __LINE__, "F(%s,%s) = %.9g vs %.9g", a->name[i],
                          a->name[j], x, y);
            test_checks++;
        }
    }
}

static double parallel_squares(double c)
{
    double X = 1 / c, Y = 1 / c;
    return 2 / (pi * X * Y) *
           (log(sqrt((1 + X * X) * (1 + Y * Y) / (1 + X * X + Y * Y))) +
            X * sqrt(1 + Y * Y) * atan(X / sqrt(1 + Y * Y)) +
            Y * sqrt(1 + X * X) * atan(Y / sqrt(1 + X * X)) - X * atan(X) - Y * atan(Y));
}

static const char cube_vertices[] =
    "V 1 0 0 0\nV 2 1 0 0\nV 3 1 1 0\nV 4 0 1 0\nV 5 0 0 1\nV 6 1 0 1\nV 7 1 1 1\nV 8 0 1 1\n";

static const char cube_obj_vertices[] =
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n";

/* Quadrilaterals: View3D's cube, and combined surfaces: its floor split in two. */
static void test_quads_and_combined(void)
{
    char text[4096];
    snprintf(text, sizeof(text),
             "T cube\nC encl=0\nF 3\n%s"
             "V 9 0.5 0 0\nV 10 0.5 1 0\n"
             "S 1 1 9 10 4 0 0 0.5 zeq0\n"
             "S 2 1 4 8 5 0 0 0.5 xeq0\nS 3 1 5 6 2 0 0 0.5 yeq0\nS 4 7 6 5 8 0 0 0.5 zeq1\n"
             "S 5 7 3 2 6 0 0 0.5 xeq1\nS 6 7 8 4 3 0 0 0.5 yeq1\n"
             "S 7 9 2 3 10 0 1 0.5 zeq0b\n"
             "End of data\n",
             cube_vertices);
    test_write_file("cube.vs3", text);
    snprintf(text, sizeof(text),
             "%sv 0.5 0 0\nv 0.5 1 0\n"
             "o zeq0\nf 1 9 10 4\nf 9 2 3 10\n"
             "o xeq0\nf 1 4 8 5\no yeq0\nf 1 5 6 2\no zeq1\nf 7 6 5 8\n"
             "o xeq1\nf 7 3 2 6\no yeq1\nf 7 8 4 3\n",
             cube_obj_vertices);
    test_write_file("cube.obj", text);
    matrix a, b;
    if (!run_mtx("cube.vs3", "cube-vs3.mtx", &a) || !run_mtx("cube.obj", "cube-obj.mtx", &b))
        return;
    CHECK(a.n == 6);
    check_same(&a, &b, 2e-4);
    double opposite = parallel_squares(1);
    CHECK_NEAR(factor(&a, "zeq0", "zeq1"), opposite, 1e-4);
    CHECK_NEAR(factor(&a, "zeq0", "xeq0"), (1 - opposite) / 4, 1e-4);
    CHECK_NEAR(a.area[index_of(&a, "zeq0")], 1.0, 1e-12);
}

/* Triangles: a closed regular-ish tetrahedron, inward-facing. */
static void test_triangles(void)
{
    const char *vs3 = "F 3\nV 1 0 0 0\nV 2 1 0 0\nV 3 0 1 0\nV 4 0 0 1\n"
                      "S 1 1 2 3 0 0 0 0.9 bottom\nS 2 1 4 2 0 0 0 0.9 front\n"
                      "S 3 1 3 4 0 0 0 0.9 side\nS 4 2 4 3 0 0 0 0.9 slope\n";
    /* each face's vertices run counter-clockwise seen from inside */
    test_write_file("tetra.vs3", vs3);
    test_write_file("tetra.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
                                 "o bottom\nf 1 2 3\no front\nf 1 4 2\no side\nf 1 3 4\n"
                                 "o slope\nf 2 4 3\n");
    matrix a, b;
    if (!run_mtx("tetra.vs3", "tetra-vs3.mtx", &a) || !run_mtx("tetra.obj", "tetra-obj.mtx", &b))
        return;
    CHECK(a.n == 4);
    check_same(&a, &b, 2e-4);
    /* a closed convex enclosure: rows sum to 1; three equal right-angle faces see the
     * slope face alike */
    for (int i = 0; i < 4; i++) {
        double row = 0;
        for (int j = 0; j < 4; j++)
            row += a.F[i][j];
        CHECK_NEAR(row, 1.0, 5e-4);
    }
    CHECK_NEAR(factor(&a, "bottom", "slope"), factor(&a, "front", "slope"), 2e-4);
    CHECK_NEAR(a.area[index_of(&a, "slope")], sqrt(3) / 2, 1e-12);
}

/* Obstruction surfaces: two parallel unit squares 1 apart with a 0.5 x 0.5 square halfway;
 * as one .vs3 and as three OBJ files with --obstruction. */
static void test_obstruction(void)
{
    test_write_file("blocked.vs3",
                    "F 3\nV 1 0 0 0\nV 2 1 0 0\nV 3 1 1 0\nV 4 0 1 0\n"
                    "V 5 0 0 1\nV 6 1 0 1\nV 7 1 1 1\nV 8 0 1 1\n"
                    "V 9 0.25 0.25 0.5\nV 10 0.75 0.25 0.5\nV 11 0.75 0.75 0.5\nV 12 0.25 0.75 0.5\n"
                    "S 1 1 2 3 4 0 0 0.9 low\nS 2 5 8 7 6 0 0 0.9 high\n"
                    "O 3 9 10 11 12 0 0 0.9 blocker\n");
    test_write_file("low.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n");
    test_write_file("high.obj", "v 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\nf 1 4 3 2\n");
    test_write_file("blocker.obj",
                    "v 0.25 0.25 0.5\nv 0.75 0.25 0.5\nv 0.75 0.75 0.5\nv 0.25 0.75 0.5\nf 1 2 3 4\n");
    matrix a, b, open;
    if (!run_mtx("blocked.vs3", "blocked-vs3.mtx", &a) ||
        !run_mtx("low.obj high.obj --obstruction blocker.obj", "blocked-obj.mtx", &b) ||
        !run_mtx("low.obj high.obj", "open.mtx", &open))
        return;
    CHECK(a.n == 2 && b.n == 2); /* the obstruction has no row or column */
    check_same(&a, &b, 2e-3);
    double unobstructed = parallel_squares(1);
    CHECK_NEAR(factor(&open, "low", "high"), unobstructed, 1e-4);
    CHECK(factor(&a, "low", "high") < 0.9 * unobstructed);
    CHECK(factor(&a, "low", "high") > 0.3 * unobstructed);
    CHECK(strstr(test_read_text(test_path("blocked-vs3.mtx")), "blocker") == NULL);
}

/* --error-bounds: each stored factor's bound, in the factors' layout; it covers the error
 * (against the closed form unobstructed, against a run 1000 times finer behind the
 * blocker) and meets the accuracy asked for. */
static void test_error_bounds(void)
{
    test_write_file("low.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n");
    test_write_file("high.obj", "v 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\nf 1 4 3 2\n");
    test_write_file("blocker.obj",
                    "v 0.25 0.25 0.5\nv 0.75 0.25 0.5\nv 0.75 0.75 0.5\nv 0.25 0.75 0.5\nf 1 2 3 4\n");
    matrix open, open_bounds, blocked, fine;
    if (!run_mtx("low.obj high.obj --error-bounds open-bounds.mtx", "open.mtx", &open) ||
        !read_mtx(test_path("open-bounds.mtx"), &open_bounds))
        return;
    CHECK(strstr(test_read_text(test_path("open-bounds.mtx")), "% error bounds of the") != NULL);
    double F = factor(&open, "low", "high"), B = factor(&open_bounds, "low", "high");
    CHECK(B > 0 && B <= 1e-4 * F); /* the bound, not the factor, and within --accuracy */
    CHECK(fabs(F - parallel_squares(1)) <= B);
    CHECK_NEAR(factor(&open_bounds, "high", "low"), B, 1e-15); /* equal areas */
    /* behind the blocker (CSV this time): the bound covers the difference from a run 1000
     * times finer, and meets the obstructed target accuracy x sqrt(F unobstructed) */
    if (!run_mtx("low.obj high.obj --obstruction blocker.obj --error-bounds blocked-bounds.csv",
                 "blocked.mtx", &blocked) ||
        !run_mtx("low.obj high.obj --obstruction blocker.obj --accuracy 1e-7", "fine.mtx", &fine))
        return;
    const char *csv = test_read_text(test_path("blocked-bounds.csv"));
    double b_low_high = -1, b_high_low = -1;
    CHECK(csv && sscanf(csv, "surface,low,high\nlow,0,%lf\nhigh,%lf,0", &b_low_high,
                        &b_high_low) == 2);
    double f = factor(&blocked, "low", "high"), exact = factor(&fine, "low", "high");
    CHECK(b_low_high > 0 && b_low_high <= 1e-4 * sqrt(parallel_squares(1)));
    CHECK(fabs(f - exact) <= b_low_high);
    CHECK(f < 0.9 * parallel_squares(1));
    CHECK_NEAR(b_high_low, b_low_high, 1e-15);
    /* a 1 x 1 square under a 2 x 2 one: each bound belongs to its row's factor, as
     * A_I F_IJ = A_J F_JI so A_I B_IJ = A_J B_JI (a transposed file fails this) */
    test_write_file("big.obj",
                    "v -0.5 -0.5 1\nv -0.5 1.5 1\nv 1.5 1.5 1\nv 1.5 -0.5 1\nf 1 2 3 4\n");
    matrix uneven, uneven_bounds;
    if (!run_mtx("low.obj big.obj --error-bounds uneven-bounds.mtx", "uneven.mtx", &uneven) ||
        !read_mtx(test_path("uneven-bounds.mtx"), &uneven_bounds))
        return;
    double up = factor(&uneven_bounds, "low", "big"), down = factor(&uneven_bounds, "big", "low");
    CHECK(up > 0 && up <= 1e-4 * factor(&uneven, "low", "big"));
    CHECK_NEAR(down, up / 4, 1e-12 * up);
    /* the factors' own file is not the bounds', however it is spelled */
    CHECK(test_run_tool("viewfactors low.obj high.obj -o same.mtx --error-bounds same.mtx") == 1);
    CHECK(strstr(test_read_text(test_path("stderr.txt")), "two outputs name one file") != NULL);
    CHECK(!test_file_exists(test_path("same.mtx")));
    char command[4096];
    snprintf(command, sizeof(command),
             "viewfactors low.obj high.obj -o same.mtx --error-bounds '%s'", test_path("same.mtx"));
    CHECK(test_run_tool(command) == 1);
    CHECK(!test_file_exists(test_path("same.mtx")));
    /* the same for any two outputs of any command: -o and --stats */
    CHECK(test_run_tool("viewfactors low.obj high.obj -o same.csv --stats ./same.csv") == 1);
    CHECK(!test_file_exists(test_path("same.csv")));
}

/* --two-sided: the middle plate of three radiates from both faces. */
static void test_two_sided(void)
{
    test_write_file("bottom.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n");
    test_write_file("middle.obj", "v 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\nf 1 4 3 2\n");
    test_write_file("top.obj", "v 0 0 2\nv 1 0 2\nv 1 1 2\nv 0 1 2\nf 1 4 3 2\n");
    matrix one, two;
    if (!run_mtx("bottom.obj middle.obj top.obj", "one.mtx", &one) ||
        !run_mtx("bottom.obj middle.obj top.obj --two-sided middle", "two.mtx", &two))
        return;
    double F = parallel_squares(1);
    CHECK_NEAR(factor(&one, "middle", "bottom"), F, 1e-4);
    CHECK(factor(&one, "middle", "top") == 0);
    CHECK(factor(&one, "bottom", "top") == 0); /* the middle plate hides it */
    CHECK_NEAR(two.area[index_of(&two, "middle")], 2.0, 1e-12);
    CHECK_NEAR(factor(&two, "middle", "top"), F / 2, 1e-4); /* top faces down (-z) */
    CHECK_NEAR(factor(&two, "top", "middle"), F, 1e-4); /* top's front faces middle's back */
    CHECK_NEAR(factor(&two, "middle", "bottom"), F / 2, 1e-4);
    CHECK(test_run_tool("viewfactors bottom.obj middle.obj --two-sided nowhere -o x.csv") == 1);
    CHECK(strstr(test_read_text(test_path("stderr.txt")), "no surface or material 'nowhere' in ") != NULL);
    CHECK(!test_file_exists(test_path("x.csv")));
}

/* --enclosure on the cube with a split floor at a coarse accuracy (rows off by about
 * 1e-3), and script-F with View3D's output layout. */
static void test_enclosure_and_script_f(void)
{
    matrix m;
    if (!run_mtx("cube.obj --enclosure --accuracy 1e-2", "closed.mtx", &m))
        return;
    const char *err = test_read_text(test_path("stderr.txt"));
    CHECK(strstr(err, "enclosure correction: largest relative change of a factor") != NULL);
    for (int i = 0; i < m.n; i++) {
        double row = 0;
        for (int j = 0; j < m.n; j++) {
            row += m.F[i][j];
            double a = m.area[i] * m.F[i][j], b = m.area[j] * m.F[j][i];
            CHECK_ABS(a - b, 0, 1e-9 * fmax(a, b));
        }
        CHECK_ABS(row, 1.0, 1e-9);
    }

    /* emit=1 in the control line: script-F in View3D's layout; rows sum to eps = 0.5 */
    char text[2048];
    snprintf(text, sizeof(text),
             "T cube\nC encl=1 emit=1\nF 3\n%s"
             "S 1 1 2 3 4 0 0 0.5 zeq0\nS 2 1 4 8 5 0 0 0.5 xeq0\nS 3 1 5 6 2 0 0 0.5 yeq0\n"
             "S 4 7 6 5 8 0 0 0.5 zeq1\nS 5 7 3 2 6 0 0 0.5 xeq1\nS 6 7 8 4 3 0 0 0.5 yeq1\n",
             cube_vertices);
    test_write_file("grey.vs3", text);
    CHECK(test_run_tool("viewfactors grey.vs3 --format view3d -o grey.txt") == 0);
    FILE *f = fopen(test_path("grey.txt"), "r");
    CHECK(f != NULL);
    if (!f)
        return;
    char line[256];
    CHECK(fgets(line, sizeof(line), f) && strncmp(line, "View3D 3.3 0 1 1 6 ", 19) == 0);
    double area[6];
    for (int k = 0; k < 6; k++)
        CHECK(fscanf(f, "%lf", &area[k]) == 1 && area[k] == 1.0);
    double S[6][6];
    for (int i = 0; i < 6; i++) {
        double row = 0;
        for (int j = 0; j < 6; j++) {
            CHECK(fscanf(f, "%lf", &S[i][j]) == 1);
            row += S[i][j];
        }
        CHECK_ABS(row, 0.5, 5e-6);
        CHECK(S[i][i] > 0); /* a flat face sees itself by reflection */
    }
    for (int i = 0; i < 6; i++)
        for (int j = 0; j < 6; j++)
            CHECK_ABS(S[i][j], S[j][i], 1e-6);
    double eps;
    CHECK(fscanf(f, "%lf", &eps) == 1 && eps == 0.5);
    fclose(f);

    /* without -o: CSV on stdout */
    CHECK(test_run_tool("viewfactors cube.vs3") == 0);
    CHECK(strncmp(test_read_text(test_path("stdout.txt")), "surface,zeq0,xeq0,", 18) == 0);
}

/* A subsurface (a 1 x 1 window in a 3 x 3 wall, View3D base = the wall) facing a parallel
 * 3 x 3 plate: the same factors as an OBJ giving the wall as four rectangles around the
 * window, and view-factor algebra: A_wall F_wall,plate + A_window F_window,plate is the
 * whole wall's transfer. */
static void test_subsurface(void)
{
    test_write_file("window.vs3",
                    "F 3\nV 1 0 0 0\nV 2 3 0 0\nV 3 3 3 0\nV 4 0 3 0\n"
                    "V 5 1 1 0\nV 6 2 1 0\nV 7 2 2 0\nV 8 1 2 0\n"
                    "V 9 0 0 1\nV 10 3 0 1\nV 11 3 3 1\nV 12 0 3 1\n"
                    "S 1 1 2 3 4 0 0 0.9 wall\nS 2 5 6 7 8 1 0 0.9 window\n"
                    "S 3 9 12 11 10 0 0 0.9 plate\n");
    test_write_file("window.obj",
                    "v 0 0 0\nv 3 0 0\nv 3 3 0\nv 0 3 0\nv 1 1 0\nv 2 1 0\nv 2 2 0\nv 1 2 0\n"
                    "v 0 0 1\nv 3 0 1\nv 3 3 1\nv 0 3 1\n"
                    "v 1 0 0\nv 2 0 0\nv 1 3 0\nv 2 3 0\n"
                    "o wall\nf 1 13 15 4\nf 13 14 6 5\nf 14 2 3 16\nf 8 7 16 15\n"
                    "o window\nf 5 6 7 8\no plate\nf 9 12 11 10\n");
    test_write_file("whole.obj", "v 0 0 0\nv 3 0 0\nv 3 3 0\nv 0 3 0\nv 0 0 1\nv 3 0 1\n"
                                 "v 3 3 1\nv 0 3 1\no wall\nf 1 2 3 4\no plate\nf 5 8 7 6\n");
    matrix a, b, whole;
    if (!run_mtx("window.vs3", "window-vs3.mtx", &a) ||
        !run_mtx("window.obj", "window-obj.mtx", &b) || !run_mtx("whole.obj", "whole.mtx", &whole))
        return;
    CHECK(a.n == 3);
    check_same(&a, &b, 2e-4);
    CHECK_NEAR(a.area[index_of(&a, "wall")], 8.0, 1e-12);
    CHECK_NEAR(8 * factor(&a, "wall", "plate") + 1 * factor(&a, "window", "plate"),
               9 * factor(&whole, "wall", "plate"), 2e-4);
    CHECK_NEAR(factor(&whole, "wall", "plate"), parallel_squares(1.0 / 3), 1e-4);
}

/* A mask (View3D M) against the same geometry with a null surface (N): the base keeps
 * its whole area and its view of the ceiling is the null version's times A_cut / A_whole;
 * the mask sees only its base. */
static void test_mask(void)
{
    const char *geometry = "F 3\nV 1 0 0 0\nV 2 2 0 0\nV 3 2 2 0\nV 4 0 2 0\n"
                           "V 5 0 0 1\nV 6 2 0 1\nV 7 2 2 1\nV 8 0 2 1\n"
                           "V 9 0.5 0.5 0\nV 10 1.5 0.5 0\nV 11 1.5 1.5 0\nV 12 0.5 1.5 0\n"
                           "S 1 1 2 3 4 0 0 0.9 floor\nS 3 5 8 7 6 0 0 0.9 ceiling\n";
    char text[1024];
    snprintf(text, sizeof(text), "%sM 2 12 11 10 9 1 0 0.4 rug\n", geometry);
    test_write_file("mask.vs3", text);
    snprintf(text, sizeof(text), "%sN 2 12 11 10 9 1 0 0.4 rug\n", geometry);
    test_write_file("null.vs3", text);
    matrix m, n;
    if (!run_mtx("mask.vs3", "mask.mtx", &m) || !run_mtx("null.vs3", "null.mtx", &n))
        return;
    CHECK(m.n == 3 && n.n == 2);
    CHECK_NEAR(m.area[index_of(&m, "floor")], 4.0, 1e-12);
    CHECK_NEAR(n.area[index_of(&n, "floor")], 3.0, 1e-12);
    CHECK_NEAR(factor(&m, "floor", "ceiling"), factor(&n, "floor", "ceiling") * 3 / 4, 1e-9);
    CHECK_NEAR(factor(&m, "ceiling", "floor"), factor(&n, "ceiling", "floor"), 1e-9);
    CHECK_NEAR(factor(&m, "rug", "floor"), 1.0, 1e-12);
    CHECK_NEAR(factor(&m, "floor", "rug"), 0.25, 1e-12);
    CHECK(factor(&m, "rug", "ceiling") == 0 && factor(&m, "ceiling", "rug") == 0);
    /* the ceiling sees the floor less the rug: less than the whole floor would give */
    double whole = parallel_squares(0.5); /* 2 x 2 squares 1 apart: X = Y = 2 */
    CHECK(factor(&m, "ceiling", "floor") < whole);
    CHECK(factor(&m, "ceiling", "floor") > 0.5 * whole);
}

static void expect_bad(const char *name, const char *body, int line, const char *words)
{
    test_write_file(name, body);
    char command[512], where[128];
    snprintf(command, sizeof(command), "viewfactors %s -o bad-out.csv", name);
    CHECK(test_run_tool(command) == 1);
    const char *err = test_read_text(test_path("stderr.txt"));
    snprintf(where, sizeof(where), "radiosity: %s:%d: ", name, line);
    if (strncmp(err, where, strlen(where)) != 0 || !strstr(err, words) ||
        strchr(err, '\n') != err + strlen(err) - 1)
        test_fail(__FILE__, __LINE__, "expected one line '%s...%s', got: %s", where, words, err);
    CHECK(!test_file_exists(test_path("bad-out.csv")));
    CHECK(test_count_files("bad-out") == 0);
}

#define SQUARE "T bad\nF 3\nV 1 0 0 0\nV 2 1 0 0\nV 3 1 1 0\nV 4 0 1 0\n"

static void test_bad_input(void)
{
    expect_bad("undefined.vs3", SQUARE "S 1 1 2 3 7 0 0 0.9 a\n", 7, "undefined vertex 7");
    expect_bad("nonplanar.vs3", SQUARE "V 5 1 1 0.2\nS 1 1 2 5 4 0 0 0.9 a\n", 8, "not planar");
    expect_bad("nonconvex.vs3", SQUARE "V 5 0.3 0.3 0\nS 1 1 2 5 4 0 0 0.9 a\n", 8,
               "not convex");
    expect_bad("zero.vs3", SQUARE "S 1 1 2 2 0 0 0 0.9 a\n", 7, "vertex 2 twice");
    expect_bad("flat.vs3", SQUARE "V 5 3 0 0\nS 1 1 2 5 0 0 0 0.9 a\n", 8, "zero area");
    expect_bad("duplicate.vs3", SQUARE "S 1 1 2 3 0 0 0 0.9 a\nS 2 1 3 4 0 0 0 0.9 a\n", 8,
               "'a' is used twice");
}

int main(void)
{
    test_quads_and_combined();
    test_triangles();
    test_obstruction();
    test_error_bounds();
    test_two_sided();
    test_enclosure_and_script_f();
    test_subsurface();
    test_mask();
    test_bad_input();
    return test_finish("test_viewfactors_io");
}
