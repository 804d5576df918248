/*
 * test_viewfactors.c - `radiosity viewfactors` on OBJ files against the closed forms of
 * shared/docs/VALIDATION.md: parallel opposed rectangles and perpendicular rectangles with
 * a common edge at several sizes and distances (1e-4 relative), F_ii = 0, reciprocity, a
 * closed unit cube (catalogue values, rows summing to 1), occluders that hide all or half,
 * a square obstruction against the test's own Monte-Carlo run, coaxial disks and
 * concentric spheres given as meshes converging to the analytic values.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "closed_forms.h"
#include "testlib.h"

/* Appends a quad "o NAME" with corners p0..p3 (counter-clockwise seen from the front). */
static void add_quad(char *obj, size_t size, int *vertices, const char *name, const double p[4][3])
{
    size_t n = strlen(obj);
    n += (size_t)snprintf(obj + n, size - n, "o %s\n", name);
    for (int k = 0; k < 4; k++)
        n += (size_t)snprintf(obj + n, size - n, "v %.17g %.17g %.17g\n", p[k][0], p[k][1], p[k][2]);
    snprintf(obj + n, size - n, "f %d %d %d %d\n", *vertices + 1, *vertices + 2, *vertices + 3,
             *vertices + 4);
    *vertices += 4;
}

/* The value at row `from`, column `to` of a view-factor CSV; NAN when absent. */
static double csv_value(const char *csv, const char *from, const char *to)
{
    const char *line = csv;
    int column = -1, k = 0;
    /* header: find the column */
    for (const char *cell = line; *cell && *cell != '\n'; k++) {
        size_t len = strcspn(cell, ",\n");
        if (strlen(to) == len && strncmp(cell, to, len) == 0 && k > 0)
            column = k;
        cell += len;
        if (*cell == ',')
            cell++;
    }
    if (column < 0)
        return NAN;
    for (line = strchr(csv, '\n'); line && line[1]; line = strchr(line + 1, '\n')) {
        const char *row = line + 1;
        size_t len = strcspn(row, ",");
        if (strlen(from) != len || strncmp(row, from, len) != 0)
            continue;
        const char *cell = row;
        for (int c = 0; c < column; c++) {
            cell = strchr(cell, ',');
            if (!cell)
                return NAN;
            cell++;
        }
        return strtod(cell, NULL);
    }
    return NAN;
}

static char obj[1 << 16];

/* Runs viewfactors on `obj` and returns the CSV text (static). */
static const char *run_viewfactors(const char *name, const char *options)
{
    char file[256], command[1024];
    snprintf(file, sizeof(file), "%s.obj", name);
    test_write_file(file, obj);
    snprintf(command, sizeof(command), "viewfactors %s.obj -o %s.csv %s", name, name, options);
    int code = test_run_tool(command);
    if (code != 0) {
        fprintf(stderr, "%s: exit %d: %s\n", name, code, test_read_text(test_path("stderr.txt")));
        test_fail(__FILE__, __LINE__, "viewfactors failed on %s", name);
    }
    snprintf(file, sizeof(file), "%s.csv", name);
    return test_read_text(test_path(file));
}

static void check_parallel(double a, double b, double c)
{
    int v = 0;
    obj[0] = 0;
    const double bottom[4][3] = {{0, 0, 0}, {a, 0, 0}, {a, b, 0}, {0, b, 0}};
    const double top[4][3] = {{0, 0, c}, {0, b, c}, {a, b, c}, {a, 0, c}};
    add_quad(obj, sizeof(obj), &v, "one", bottom);
    add_quad(obj, sizeof(obj), &v, "two", top);
    const char *csv = run_viewfactors("parallel", "");
    double expected = parallel_rectangles(a, b, c);
    printf("parallel %gx%g at %g: F12 %.7f F21 %.7f expected %.7f\n", a, b, c,
           csv_value(csv, "one", "two"), csv_value(csv, "two", "one"), expected);
    CHECK_NEAR(csv_value(csv, "one", "two"), expected, 1e-4);
    CHECK_NEAR(csv_value(csv, "two", "one"), expected, 1e-4);
    CHECK(csv_value(csv, "one", "one") == 0);
    CHECK(csv_value(csv, "two", "two") == 0);
}

static void check_perpendicular(double w, double h, double l)
{
    int v = 0;
    obj[0] = 0;
    /* surface one in z = 0 (w along y) facing +z; surface two in y = 0 (h along z) facing +y */
    const double one[4][3] = {{0, 0, 0}, {l, 0, 0}, {l, w, 0}, {0, w, 0}};
    const double two[4][3] = {{0, 0, 0}, {0, 0, h}, {l, 0, h}, {l, 0, 0}};
    add_quad(obj, sizeof(obj), &v, "one", one);
    add_quad(obj, sizeof(obj), &v, "two", two);
    const char *csv = run_viewfactors("perpendicular", "");
    double f12 = csv_value(csv, "one", "two"), f21 = csv_value(csv, "two", "one");
    double expected = perpendicular_rectangles(w, h, l);
    printf("perpendicular w=%g h=%g l=%g: F12 %.7f expected %.7f\n", w, h, l, f12, expected);
    CHECK_NEAR(f12, expected, 1e-4);
    /* reciprocity: A1 F12 = A2 F21, and F21 against its own closed form */
    CHECK_NEAR(w * l * f12, h * l * f21, 1e-7);
    CHECK_NEAR(f21, perpendicular_rectangles(h, w, l), 1e-4);
    CHECK(csv_value(csv, "one", "one") == 0);
}

static void check_cube(void)
{
    int v = 0;
    obj[0] = 0;
    /* inward-facing unit cube */
    const double faces[6][4][3] = {
        {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}},  /* z = 0, faces +z */
        {{0, 0, 1}, {0, 1, 1}, {1, 1, 1}, {1, 0, 1}},  /* z = 1, faces -z */
        {{0, 0, 0}, {0, 1, 0}, {0, 1, 1}, {0, 0, 1}},  /* x = 0, faces +x */
        {{1, 0, 0}, {1, 0, 1}, {1, 1, 1}, {1, 1, 0}},  /* x = 1, faces -x */
        {{0, 0, 0}, {0, 0, 1}, {1, 0, 1}, {1, 0, 0}},  /* y = 0, faces +y */
        {{0, 1, 0}, {1, 1, 0}, {1, 1, 1}, {0, 1, 1}},  /* y = 1, faces -y */
    };
    const char *names[6] = {"zlo", "zhi", "xlo", "xhi", "ylo", "yhi"};
    for (int f = 0; f < 6; f++)
        add_quad(obj, sizeof(obj), &v, names[f], faces[f]);
    const char *csv = run_viewfactors("cube", "");
    double opposite = parallel_rectangles(1, 1, 1), adjacent = perpendicular_rectangles(1, 1, 1);
    CHECK_NEAR(opposite, 0.1998249, 1e-6);
    CHECK_NEAR(adjacent, 0.2000438, 1e-6);
    for (int i = 0; i < 6; i++) {
        double row = 0;
        for (int j = 0; j < 6; j++) {
            double F = csv_value(csv, names[i], names[j]);
            row += F;
            if (i == j)
                CHECK(F == 0);
            else if (i / 2 == j / 2)
                CHECK_NEAR(F, opposite, 1e-4);
            else
                CHECK_NEAR(F, adjacent, 1e-4);
        }
        CHECK_NEAR(row, 1.0, 1e-4);
    }
}

/* Two unit plates 1 apart; a blocker at mid-height either covers everything or, by
 * symmetry, exactly half: a segment from p to q is blocked iff its midpoint is in the
 * blocker, and the point reflection through the centre maps blocked to unblocked. */
static void check_occluders(void)
{
    const double bottom[4][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    const double top[4][3] = {{0, 0, 1}, {0, 1, 1}, {1, 1, 1}, {1, 0, 1}};
    const double everything[4][3] = {{-2, -2, 0.5}, {3, -2, 0.5}, {3, 3, 0.5}, {-2, 3, 0.5}};
    const double half[4][3] = {{-2, -2, 0.5}, {0.5, -2, 0.5}, {0.5, 3, 0.5}, {-2, 3, 0.5}};
    double unoccluded = parallel_rectangles(1, 1, 1);
    int v = 0;
    obj[0] = 0;
    add_quad(obj, sizeof(obj), &v, "one", bottom);
    add_quad(obj, sizeof(obj), &v, "two", top);
    add_quad(obj, sizeof(obj), &v, "blocker", everything);
    const char *csv = run_viewfactors("hidden", "");
    CHECK(csv_value(csv, "one", "two") == 0);
    CHECK(csv_value(csv, "two", "one") == 0);

    v = 0;
    obj[0] = 0;
    add_quad(obj, sizeof(obj), &v, "one", bottom);
    add_quad(obj, sizeof(obj), &v, "two", top);
    add_quad(obj, sizeof(obj), &v, "blocker", half);
    csv = run_viewfactors("half", "");
    printf("half blocker: F12 %.7f, half of unoccluded %.7f\n", csv_value(csv, "one", "two"),
           unoccluded / 2);
    CHECK_NEAR(csv_value(csv, "one", "two"), unoccluded / 2, 0.02);
    CHECK_NEAR(csv_value(csv, "two", "one"), unoccluded / 2, 0.02);
    /* obstructed never above unobstructed, and the blocker's front (facing +z) sees plate two */
    CHECK(csv_value(csv, "one", "two") <= unoccluded);
    CHECK(csv_value(csv, "blocker", "two") > 0);
}

/* Coaxial parallel disks as triangle fans (VALIDATION.md section 1). The fan polygon has
 * a little less area than the disk; the disk of equal area is the reference. */
static double coaxial_disks(double r1, double r2, double L)
{
    double R1 = r1 / L, R2 = r2 / L, S = 1 + (1 + R2 * R2) / (R1 * R1);
    return 0.5 * (S - sqrt(S * S - 4 * (r2 / r1) * (r2 / r1)));
}

static void check_disks(double r1, double r2, double L)
{
    enum { SEGMENTS = 96 };
    size_t n = 0;
    obj[0] = 0;
    /* disk one at z = 0 facing +z, disk two at z = L facing -z */
    for (int d = 0; d < 2; d++) {
        double r = d ? r2 : r1, z = d ? L : 0;
        n += (size_t)snprintf(obj + n, sizeof(obj) - n, "o disk%d\nv 0 0 %.17g\n", d + 1, z);
        for (int k = 0; k < SEGMENTS; k++) {
            double a = 2 * pi * k / SEGMENTS;
            n += (size_t)snprintf(obj + n, sizeof(obj) - n, "v %.17g %.17g %.17g\n", r * cos(a),
                                  r * sin(a), z);
        }
        int centre = d * (SEGMENTS + 1) + 1;
        for (int k = 0; k < SEGMENTS; k++) {
            int a = centre + 1 + k, b = centre + 1 + (k + 1) % SEGMENTS;
            if (d == 0)
                n += (size_t)snprintf(obj + n, sizeof(obj) - n, "f %d %d %d\n", centre, a, b);
            else
                n += (size_t)snprintf(obj + n, sizeof(obj) - n, "f %d %d %d\n", centre, b, a);
        }
    }
    const char *csv = run_viewfactors("disks", "");
    double shrink = sqrt(SEGMENTS * sin(2 * pi / SEGMENTS) / (2 * pi)); /* equal-area radius */
    double expected = coaxial_disks(r1 * shrink, r2 * shrink, L);
    printf("coaxial disks r1=%g r2=%g L=%g: F12 %.7f expected %.7f (disk %.7f)\n", r1, r2, L,
           csv_value(csv, "disk1", "disk2"), expected, coaxial_disks(r1, r2, L));
    CHECK_NEAR(csv_value(csv, "disk1", "disk2"), expected, 0.005);
    CHECK_NEAR(csv_value(csv, "disk1", "disk2"), coaxial_disks(r1, r2, L), 0.005);
    /* reciprocity through the areas of the two fans */
    CHECK_NEAR(r1 * r1 * csv_value(csv, "disk1", "disk2"), r2 * r2 * csv_value(csv, "disk2", "disk1"),
               1e-6);
}

/* One-sided surfaces: plates that turn their backs on each other exchange nothing. */
static void check_one_sided(void)
{
    int v = 0;
    obj[0] = 0;
    const double bottom[4][3] = {{0, 0, 0}, {0, 1, 0}, {1, 1, 0}, {1, 0, 0}}; /* faces -z */
    const double top[4][3] = {{0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};    /* faces +z */
    add_quad(obj, sizeof(obj), &v, "one", bottom);
    add_quad(obj, sizeof(obj), &v, "two", top);
    const char *csv = run_viewfactors("backs", "");
    CHECK(csv_value(csv, "one", "two") == 0);
    CHECK(csv_value(csv, "two", "one") == 0);
}

/* A number from a --stats JSON file ("key": value). */
static double stats_value(const char *path, const char *key)
{
    const char *json = test_read_text(path);
    char pattern[128];
    snprintf(pattern, sizeof(pattern), "\"%s\":", key);
    const char *at = strstr(json, pattern);
    return at ? strtod(at + strlen(pattern), NULL) : NAN;
}

/* The obstructed case: unit squares 1 apart, a 0.5 x 0.5 square centred halfway.
 * The reference is the test's own Monte-Carlo run: cosine-distributed rays from uniform
 * points of the bottom square, counted when they reach the top square past the blocker.
 * The blocker is one quad (two triangles: shadows clipped exactly) or split n x n (2 n^2
 * triangles, more than --exact-occluders 4 clips: visibility sampled, with its error
 * bound; the default clips them all, checked by test_viewfactor_obstructed). */
static void check_obstruction_monte_carlo(int split)
{
    const double bottom[4][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    const double top[4][3] = {{0, 0, 1}, {0, 1, 1}, {1, 1, 1}, {1, 0, 1}};
    const double blocker[4][3] = {{0.25, 0.25, 0.5}, {0.25, 0.75, 0.5}, {0.75, 0.75, 0.5},
                                  {0.75, 0.25, 0.5}};
    int v = 0;
    obj[0] = 0;
    add_quad(obj, sizeof(obj), &v, "one", bottom);
    add_quad(obj, sizeof(obj), &v, "two", top);
    size_t n = strlen(obj);
    n += (size_t)snprintf(obj + n, sizeof(obj) - n, "o blocker\n");
    for (int i = 0; i < split; i++)
        for (int j = 0; j < split; j++) {
            double x0 = 0.25 + 0.5 * i / split, x1 = 0.25 + 0.5 * (i + 1) / split;
            double y0 = 0.25 + 0.5 * j / split, y1 = 0.25 + 0.5 * (j + 1) / split;
            n += (size_t)snprintf(obj + n, sizeof(obj) - n,
                                  "v %.17g %.17g 0.5\nv %.17g %.17g 0.5\nv %.17g %.17g 0.5\n"
                                  "v %.17g %.17g 0.5\nf %d %d %d %d\n",
                                  x0, y0, x0, y1, x1, y1, x1, y0, v + 1, v + 2, v + 3, v + 4);
            v += 4;
        }
    (void)blocker;
    const char *csv = run_viewfactors("obstructed", "--exact-occluders 4 --stats obstructed.json");
    double F = csv_value(csv, "one", "two");
    double bound = stats_value(test_path("obstructed.json"), "largest_error_bound");
    /* the sampled pair's bound is above its target: said, and counted in --stats (the
     * text last, as test_read_text's buffer is the CSV's) */
    CHECK(stats_value(test_path("obstructed.json"), "short_pairs") == (split == 1 ? 0 : 1));
    const char *said = test_read_text(test_path("stderr.txt"));
    const char *expected = split == 1 ? "every factor within --accuracy"
                                      : "1 of 5 polygon pairs short of --accuracy";
    CHECK(strstr(said, expected) != NULL);
    if (!strstr(said, expected))
        fprintf(stderr, "expected '%s' in: %s", expected, said);

    uint64_t state = 0x9E3779B97F4A7C15ull, hits = 0, samples = 4000000;
    for (uint64_t k = 0; k < samples; k++) {
        double u[4];
        for (int d = 0; d < 4; d++) {
            state ^= state << 13, state ^= state >> 7, state ^= state << 17;
            u[d] = (double)(state >> 11) * (1.0 / 9007199254740992.0);
        }
        double r = sqrt(u[2]), phi = 2 * pi * u[3];
        double dx = r * cos(phi), dy = r * sin(phi), dz = sqrt(fmax(0, 1 - u[2]));
        double x1 = u[0] + dx / dz, y1 = u[1] + dy / dz;
        double xm = u[0] + 0.5 * dx / dz, ym = u[1] + 0.5 * dy / dz;
        bool reaches = x1 >= 0 && x1 <= 1 && y1 >= 0 && y1 <= 1;
        bool blocked = xm >= 0.25 && xm <= 0.75 && ym >= 0.25 && ym <= 0.75;
        hits += reaches && !blocked;
    }
    double reference = (double)hits / (double)samples;
    double standard_error = sqrt(reference * (1 - reference) / (double)samples);
    double sampled = stats_value(test_path("obstructed.json"), "sampled_pairs");
    printf("square obstruction as %d x %d: F12 %.6f (bound %.2g, %g pairs sampled), Monte "
           "Carlo %.6f +- %.2g, unobstructed %.6f\n", split, split, F, bound, sampled,
           reference, standard_error, parallel_rectangles(1, 1, 1));
    CHECK(fabs(F - reference) <= 3 * standard_error + bound);
    CHECK(bound > 0 && bound < (split == 1 ? 1e-4 : 2e-2)); /* absolute, largest of all */
    CHECK(sampled == (split == 1 ? 0 : 1));
    CHECK(F < parallel_rectangles(1, 1, 1));
}

/* A regular polygon fan of `segments` triangles approximating a disk of radius r at
 * height z, facing up (+z) or down. */
static size_t add_fan(size_t n, const char *name, double r, double z, bool up, int segments,
                      int *vertices)
{
    n += (size_t)snprintf(obj + n, sizeof(obj) - n, "o %s\nv 0 0 %.17g\n", name, z);
    for (int k = 0; k < segments; k++) {
        double a = 2 * pi * k / segments;
        n += (size_t)snprintf(obj + n, sizeof(obj) - n, "v %.17g %.17g %.17g\n", r * cos(a),
                              r * sin(a), z);
    }
    int centre = *vertices + 1;
    for (int k = 0; k < segments; k++) {
        int a = centre + 1 + k, b = centre + 1 + (k + 1) % segments;
        n += (size_t)snprintf(obj + n, sizeof(obj) - n, "f %d %d %d\n", centre, up ? a : b,
                              up ? b : a);
    }
    *vertices += segments + 1;
    return n;
}

/* A curved or many-sided surface given as a fine mesh converges to the analytic value. */
static void check_disk_convergence(void)
{
    const int levels[3] = {16, 64, 256};
    double error[3];
    for (int l = 0; l < 3; l++) {
        int v = 0;
        obj[0] = 0;
        size_t n = add_fan(0, "disk1", 1, 0, true, levels[l], &v);
        add_fan(n, "disk2", 1, 1, false, levels[l], &v);
        const char *csv = run_viewfactors("fans", "");
        error[l] = fabs(csv_value(csv, "disk1", "disk2") / coaxial_disks(1, 1, 1) - 1);
        printf("coaxial disks as %d-gons: relative error %.2e\n", levels[l], error[l]);
    }
    CHECK(error[1] < error[0] / 8 && error[2] < error[1] / 8);
    CHECK(error[2] < 1e-4);
}

static double sphere_point(double r, int bands, int b, int s, int axis)
{
    double theta = pi * b / bands, phi = 2 * pi * s / (2 * bands);
    return axis == 0 ? r * sin(theta) * cos(phi) : axis == 1 ? r * sin(theta) * sin(phi)
                                                            : r * cos(theta);
}

static double triangle_area(const double a[3], const double b[3], const double c[3])
{
    double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    double x = u[1] * v[2] - u[2] * v[1], y = u[2] * v[0] - u[0] * v[2],
           z = u[0] * v[1] - u[1] * v[0];
    return 0.5 * sqrt(x * x + y * y + z * z);
}

/* The area of the UV sphere add_sphere writes: its triangles and (flat) quads. */
static double uv_sphere_area(double r, int bands)
{
    double area = 0;
    for (int s = 0; s < 2 * bands; s++)
        for (int b = 0; b < bands; b++) {
            double p[4][3];
            for (int a = 0; a < 3; a++) {
                p[0][a] = sphere_point(r, bands, b, s, a);
                p[1][a] = sphere_point(r, bands, b + 1, s, a);
                p[2][a] = sphere_point(r, bands, b + 1, s + 1, a);
                p[3][a] = sphere_point(r, bands, b, s + 1, a);
            }
            /* at the poles one of the two is degenerate and adds nothing */
            area += triangle_area(p[0], p[1], p[2]) + triangle_area(p[0], p[2], p[3]);
        }
    return area;
}

/* A UV sphere of radius r, facing out (or in), with `bands` latitude bands. */
static size_t add_sphere(size_t n, const char *name, double r, bool outward, int bands,
                         int *vertices)
{
    int segments = 2 * bands;
    n += (size_t)snprintf(obj + n, sizeof(obj) - n, "o %s\nv 0 0 %.17g\n", name, r);
    for (int b = 1; b < bands; b++)
        for (int s = 0; s < segments; s++)
            n += (size_t)snprintf(obj + n, sizeof(obj) - n, "v %.17g %.17g %.17g\n",
                                  sphere_point(r, bands, b, s, 0),
                                  sphere_point(r, bands, b, s, 1),
                                  sphere_point(r, bands, b, s, 2));
    n += (size_t)snprintf(obj + n, sizeof(obj) - n, "v 0 0 %.17g\n", -r);
    int north = *vertices + 1, south = north + 1 + (bands - 1) * segments;
#define RING(b, s) (north + 1 + ((b) - 1) * segments + ((s) % segments))
    for (int s = 0; s < segments; s++) {
        /* counter-clockwise seen from outside */
        int face[2][4] = {{north, RING(1, s), RING(1, s + 1), 0},
                          {south, RING(bands - 1, s + 1), RING(bands - 1, s), 0}};
        for (int f = 0; f < 2; f++)
            n += (size_t)snprintf(obj + n, sizeof(obj) - n, "f %d %d %d\n", face[f][0],
                                  outward ? face[f][1] : face[f][2],
                                  outward ? face[f][2] : face[f][1]);
        for (int b = 1; b + 1 < bands; b++) {
            int q[4] = {RING(b, s), RING(b + 1, s), RING(b + 1, s + 1), RING(b, s + 1)};
            if (outward)
                n += (size_t)snprintf(obj + n, sizeof(obj) - n, "f %d %d %d %d\n", q[0], q[1],
                                      q[2], q[3]);
            else
                n += (size_t)snprintf(obj + n, sizeof(obj) - n, "f %d %d %d %d\n", q[3], q[2],
                                      q[1], q[0]);
        }
    }
#undef RING
    *vertices = south;
    return n;
}

/* Concentric spheres (VALIDATION.md section 1): F_12 = 1, F_21 = (r1/r2)^2 and
 * F_22 = 1 - (r1/r2)^2 -- the outer sphere sees itself, around the inner one. For the
 * meshes, F_12 = 1 and reciprocity make F_21 = A_1/A_2 exactly, and F_22 = 1 - F_21; the
 * analytic values are approached as the meshes are refined. */
static void check_concentric_spheres(void)
{
    const int inner_bands = 4, outer_bands = 8;
    int v = 0;
    obj[0] = 0;
    size_t n = add_sphere(0, "inner", 0.5, true, inner_bands, &v);
    add_sphere(n, "outer", 1, false, outer_bands, &v);
    const char *csv = run_viewfactors("spheres", "--stats spheres.json");
    double f12 = csv_value(csv, "inner", "outer"), f21 = csv_value(csv, "outer", "inner");
    double f22 = csv_value(csv, "outer", "outer"), f11 = csv_value(csv, "inner", "inner");
    /* (stats_value reads into the buffer csv points to) */
    double bound = stats_value(test_path("spheres.json"), "largest_error_bound");
    double ratio = uv_sphere_area(0.5, inner_bands) / uv_sphere_area(1, outer_bands);
    printf("concentric spheres: F12 %.6f F21 %.6f (A1/A2 %.6f) F22 %.6f (1 - A1/A2 %.6f; "
           "analytic 0.25, 0.75; bound %.2g)\n", f12, f21, ratio, f22, 1 - ratio, bound);
    CHECK_NEAR(f12, 1, 1e-4);
    CHECK(f11 == 0);
    CHECK_NEAR(f21, ratio, 1e-4);
    CHECK(fabs(f22 - (1 - ratio)) <= 2 * bound + 1e-4);
    CHECK(bound < 1e-2);
    CHECK_NEAR(f21, 0.25, 0.15); /* coarse meshes: the analytic limit only roughly */
    CHECK_NEAR(f22, 0.75, 0.05);

    /* the same bits for any thread count: sampled pairs are seeded by the pair */
    static char one_thread[1 << 12];
    snprintf(one_thread, sizeof(one_thread), "%s", run_viewfactors("spheres", "--threads 1"));
    CHECK(strcmp(one_thread, run_viewfactors("spheres", "--threads 3")) == 0);
}

int main(void)
{
    CHECK_NEAR(parallel_rectangles(1, 1, 1), 0.1998249, 1e-6);
    CHECK_NEAR(parallel_rectangles(0.1, 0.1, 1), 0.00316206, 1e-5);
    CHECK_NEAR(parallel_rectangles(2, 1, 1), 0.2858754, 1e-6);
    CHECK_NEAR(perpendicular_rectangles(2, 1, 1), 0.1164263, 1e-6);
    CHECK_NEAR(perpendicular_rectangles(1, 2, 1), 0.2328526, 1e-6);

    check_parallel(1, 1, 1);
    check_parallel(0.1, 0.1, 1);
    check_parallel(2, 1, 1);
    check_parallel(3, 0.5, 0.25);
    check_parallel(1, 1, 10);
    check_perpendicular(1, 1, 1);
    check_perpendicular(2, 1, 1);
    check_perpendicular(1, 2, 1);
    check_perpendicular(0.2, 3, 1.5);
    check_cube();
    check_occluders();
    check_disks(1, 1, 1);
    check_disks(0.5, 2, 1);
    check_one_sided();
    check_obstruction_monte_carlo(1);
    check_obstruction_monte_carlo(4);
    check_disk_convergence();
    check_concentric_spheres();
    return test_finish("test_viewfactors");
}
