/*
 * test_sky_viewfactor.c - `radiosity viewfactors --sky-view-factor` against closed forms
 * and an independent count: the floor and walls of an urban canyon (1 - the factors to the
 * walls, from the perpendicular and parallel rectangle formulas of VALIDATION.md, at 1e-4
 * relative; the infinitely long canyon's sqrt(1 + (H/W)^2) - H/W as the length grows), a
 * canyon crossed by a beam against the test's own brute-force Monte-Carlo count over every
 * triangle (within 4 sigma plus the reported bound), a floor under a grid of 400 squares
 * with --sky-exact (its tiles clipped on a second try) against a count of its own, a flat
 * plate (1), a closed box (0),
 * row sum + SVF = 1, the CSV and Matrix Market companion layouts with an obstruction left
 * out, and the same bytes for 1 and 2 threads.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/random.h"
#include "closed_forms.h"
#include "testlib.h"

/* The scene as quads (counter-clockwise seen from the front), each quad an object unless
 * it continues the previous one's object (name NULL). */
enum { MAX_QUADS = 512 };
static double quads[MAX_QUADS][4][3];
static const char *quad_names[MAX_QUADS];
static int quad_count;

static void add_quad(const char *name, double a0, double a1, double a2, double b0, double b1,
                     double b2, double c0, double c1, double c2, double d0, double d1,
                     double d2)
{
    double p[4][3] = {{a0, a1, a2}, {b0, b1, b2}, {c0, c1, c2}, {d0, d1, d2}};
    memcpy(quads[quad_count], p, sizeof(p));
    quad_names[quad_count++] = name;
}

static const char *write_obj(const char *file)
{
    static char obj[1 << 18];
    size_t n = 0;
    obj[0] = 0;
    for (int q = 0; q < quad_count; q++) {
        if (quad_names[q])
            n += (size_t)snprintf(obj + n, sizeof(obj) - n, "o %s\n", quad_names[q]);
        for (int k = 0; k < 4; k++)
            n += (size_t)snprintf(obj + n, sizeof(obj) - n, "v %.17g %.17g %.17g\n",
                                  quads[q][k][0], quads[q][k][1], quads[q][k][2]);
        n += (size_t)snprintf(obj + n, sizeof(obj) - n, "f %d %d %d %d\n", 4 * q + 1, 4 * q + 2,
                              4 * q + 3, 4 * q + 4);
    }
    return test_write_file(file, obj);
}

/* Row `name` of a sky CSV: its index, SVF and bound; false when absent. */
static bool sky_row(const char *csv, const char *name, int *index, double *svf, double *bound)
{
    if (strncmp(csv, "index,surface,sky_view_factor,error_bound\n", 42) != 0)
        return false;
    for (const char *line = strchr(csv, '\n'); line && line[1]; line = strchr(line + 1, '\n')) {
        char row_name[128];
        int k;
        if (sscanf(line + 1, "%d,%127[^,],%lf,%lf", &k, row_name, svf, bound) == 4 &&
            strcmp(row_name, name) == 0) {
            *index = k;
            return true;
        }
    }
    return false;
}

/* Sum of row `name` of a view-factor CSV. */
static double row_sum(const char *csv, const char *name)
{
    for (const char *line = strchr(csv, '\n'); line && line[1]; line = strchr(line + 1, '\n')) {
        const char *row = line + 1;
        size_t len = strcspn(row, ",");
        if (strlen(name) != len || strncmp(row, name, len) != 0)
            continue;
        double sum = 0;
        for (const char *cell = strchr(row, ','); cell && *cell == ',';) {
            char *end;
            sum += strtod(cell + 1, &end);
            cell = end;
        }
        return sum;
    }
    return NAN;
}

/* The value after `key` in the tool's stderr; NAN when absent. */
static double stderr_value(const char *key)
{
    const char *text = test_read_text(test_path("stderr.txt"));
    const char *at = strstr(text, key);
    return at ? strtod(at + strlen(key), NULL) : NAN;
}

static bool run(const char *arguments)
{
    int code = test_run_tool(arguments);
    if (code != 0)
        fprintf(stderr, "exit %d: %s\n", code, test_read_text(test_path("stderr.txt")));
    return code == 0;
}

/* Floor W x L (z = 0, up), walls of height H at x = 0 and x = W facing in. */
static void canyon(double W, double H, double L)
{
    quad_count = 0;
    add_quad("floor", 0, 0, 0, W, 0, 0, W, L, 0, 0, L, 0);
    add_quad("west", 0, 0, 0, 0, L, 0, 0, L, H, 0, 0, H);
    add_quad("east", W, 0, 0, W, 0, H, W, L, H, W, L, 0);
}

static void check_canyon(double W, double H, double L)
{
    canyon(W, H, L);
    write_obj("canyon.obj");
    CHECK(run("viewfactors canyon.obj -o canyon.csv --sky-view-factor canyon-sky.csv"));
    char sky[4096];
    snprintf(sky, sizeof(sky), "%s", test_read_text(test_path("canyon-sky.csv")));
    const char *F = test_read_text(test_path("canyon.csv"));
    double floor_expected = 1 - 2 * perpendicular_rectangles(W, H, L);
    double wall_expected = 1 - perpendicular_rectangles(H, W, L) - parallel_rectangles(H, L, W);
    double infinite = sqrt(1 + (H / W) * (H / W)) - H / W;
    int index;
    double svf, bound;
    CHECK(sky_row(sky, "floor", &index, &svf, &bound) && index == 1);
    printf("canyon H/W %g, L/W %g: floor SVF %.9f (bound %.2g), closed form %.9f, infinitely "
           "long %.9f\n",
           H / W, L / W, svf, bound, floor_expected, infinite);
    CHECK_NEAR(svf, floor_expected, 1e-4);
    CHECK(fabs(svf - floor_expected) <= bound + 1e-9);
    CHECK(bound <= 1e-4 * svf);
    /* the finite canyon tends to the infinite one: no further from it than the closed form */
    CHECK(fabs(svf - infinite) <= fabs(floor_expected - infinite) + 1e-4 * svf);
    CHECK_NEAR(row_sum(F, "floor") + svf, 1, 1e-4);
    const char *walls[2] = {"west", "east"};
    for (int k = 0; k < 2; k++) {
        CHECK(sky_row(sky, walls[k], &index, &svf, &bound) && index == k + 2);
        printf("  %s SVF %.9f (bound %.2g), closed form %.9f\n", walls[k], svf, bound,
               wall_expected);
        CHECK_NEAR(svf, wall_expected, 1e-4);
        CHECK(bound <= 1e-4 * svf);
        CHECK_NEAR(row_sum(F, walls[k]) + svf, 1, 1e-4);
    }
    double deviation = stderr_value("largest |row sum + SVF - 1| ");
    printf("  printed largest |row sum + SVF - 1| %.3g\n", deviation);
    CHECK(deviation >= 0 && deviation <= 1e-4);
    CHECK(strstr(test_read_text(test_path("stderr.txt")),
                 "sky view factors: every one within --accuracy 0.0001 (absolute)") != NULL);
}

/* Does the ray (o, d) hit triangle (a, b, c) at t > 1e-9 (test_ray_triangle)? */
static bool hits(const double o[3], const double d[3], const double a[3], const double b[3],
                 const double c[3])
{
    const rad_vec3 at = {a[0], a[1], a[2]}, bt = {b[0], b[1], b[2]}, ct = {c[0], c[1], c[2]};
    double t = test_ray_triangle((rad_vec3){o[0], o[1], o[2]}, (rad_vec3){d[0], d[1], d[2]},
                                 at, bt, ct, NULL, NULL);
    return t > 1e-9 && t < INFINITY;
}

/* The share of cosine-distributed rays from uniform points of quad 0 (flat, facing +z)
 * that meet no triangle of the other quads; *sigma its standard error. */
static double monte_carlo_sky(uint32_t rays, double *sigma)
{
    rad_rng rng = rad_rng_seed(17, 0, 0);
    uint32_t escaped = 0;
    double(*f)[3] = quads[0];
    for (uint32_t r = 0; r < rays; r++) {
        double s = rad_rng_uniform(&rng), t = rad_rng_uniform(&rng);
        double o[3], d[3];
        /* floor quads are axis-aligned rectangles: corners 0 and 2 span them */
        for (int k = 0; k < 3; k++)
            o[k] = f[0][k] + s * (f[1][k] - f[0][k]) + t * (f[3][k] - f[0][k]);
        double u = rad_rng_uniform(&rng), phi = 2 * pi * rad_rng_uniform(&rng);
        double radius = sqrt(u);
        d[0] = radius * cos(phi), d[1] = radius * sin(phi), d[2] = sqrt(1 - u);
        bool blocked = false;
        for (int q = 1; q < quad_count && !blocked; q++)
            blocked = hits(o, d, quads[q][0], quads[q][1], quads[q][2]) ||
                      hits(o, d, quads[q][0], quads[q][2], quads[q][3]);
        escaped += !blocked;
    }
    double p = (double)escaped / rays;
    *sigma = sqrt(p * (1 - p) / rays);
    return p;
}

/* A canyon (W 1, H 1, L 4) crossed by a beam (a closed box, 0.6 to 0.8 high, 1.8 to 2.2
 * along it): no closed form; the floor's SVF against the test's own count. */
static void check_canyon_with_beam(void)
{
    canyon(1, 1, 4);
    double y0 = 1.8, y1 = 2.2, z0 = 0.6, z1 = 0.8;
    add_quad("beam", 0, y0, z0, 0, y1, z0, 1, y1, z0, 1, y0, z0); /* bottom, facing -z */
    add_quad(NULL, 0, y0, z1, 1, y0, z1, 1, y1, z1, 0, y1, z1);   /* top */
    add_quad(NULL, 0, y0, z0, 1, y0, z0, 1, y0, z1, 0, y0, z1);   /* -y side */
    add_quad(NULL, 0, y1, z0, 0, y1, z1, 1, y1, z1, 1, y1, z0);   /* +y side */
    write_obj("beam.obj");
    CHECK(run("viewfactors beam.obj -o beam.csv --sky-view-factor beam-sky.csv"));
    const char *sky = test_read_text(test_path("beam-sky.csv"));
    int index;
    double svf = NAN, bound = NAN, sigma;
    CHECK(sky_row(sky, "floor", &index, &svf, &bound));
    double reference = monte_carlo_sky(1u << 20, &sigma);
    printf("canyon with a beam: floor SVF %.6f (bound %.2g), Monte Carlo %.6f +- %.2g\n", svf,
           bound, reference, sigma);
    CHECK(fabs(svf - reference) <= 4 * sigma + bound);
    CHECK_NEAR(row_sum(test_read_text(test_path("beam.csv")), "floor") + svf, 1,
               1e-4 + bound);
}

/* A floor under a grid of 7 x 7 small squares (98 triangles, one surface facing up): the
 * sky behind more than 16 triangles is sampled, so the floor's SVF is short of the
 * accuracy and the run says so (the grid's own, open above, is exact); with --sky-exact it
 * is clipped, within the accuracy. Both against the test's own count (2^22 rays: s.e.
 * about 2e-4). */
static void check_sampled_sky(void)
{
    quad_count = 0;
    add_quad("floor", 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0);
    for (int i = 0; i < 7; i++)
        for (int j = 0; j < 7; j++) {
            double x = (i + 0.25) / 7, y = (j + 0.25) / 7, h = 0.5 / 7, z = 0.15;
            add_quad(i + j ? NULL : "grid", x, y, z, x + h, y, z, x + h, y + h, z, x, y + h, z);
        }
    write_obj("grid.obj");
    CHECK(run("viewfactors grid.obj -o grid.csv --sky-view-factor grid-sky.csv --stats "
              "grid.json"));
    const char *text = test_read_text(test_path("stderr.txt"));
    printf("%s", text);
    CHECK(strstr(text, "sky view factors: 1 of 2 short of --accuracy 0.0001 (their bound above "
                       "it, absolute)") != NULL);
    CHECK(strstr(test_read_text(test_path("grid.json")), "\"sky_short_surfaces\": 1") != NULL);
    const char *sky = test_read_text(test_path("grid-sky.csv"));
    int index;
    double svf = NAN, bound = NAN, sigma;
    CHECK(sky_row(sky, "grid", &index, &svf, &bound));
    CHECK_NEAR(svf, 1, 1e-9);
    CHECK(bound <= 1e-4);
    CHECK(sky_row(sky, "floor", &index, &svf, &bound));
    CHECK(bound > 1e-4);
    double reference = monte_carlo_sky(1u << 22, &sigma);
    printf("floor under a grid: SVF %.6f (bound %.2g), Monte Carlo %.6f +- %.2g\n", svf, bound,
           reference, sigma);
    CHECK(fabs(svf - reference) <= 4 * sigma + bound);
    /* --sky-exact: clipped, every one within */
    CHECK(run("viewfactors grid.obj -o grid.csv --sky-view-factor grid-exact.csv --sky-exact "
              "--stats grid.json"));
    text = test_read_text(test_path("stderr.txt"));
    printf("%s", text);
    CHECK(strstr(text, "sky view factors: every one within --accuracy 0.0001 (absolute)") != NULL);
    CHECK(strstr(test_read_text(test_path("grid.json")), "\"sky_short_surfaces\": 0") != NULL);
    sky = test_read_text(test_path("grid-exact.csv"));
    CHECK(sky_row(sky, "floor", &index, &svf, &bound));
    printf("floor under a grid, --sky-exact: SVF %.6f (bound %.2g), Monte Carlo %.6f +- %.2g\n",
           svf, bound, reference, sigma);
    CHECK(bound <= 1e-4);
    CHECK(fabs(svf - reference) <= 4 * sigma + bound);
    /* it asks for the sky view factors */
    CHECK(test_run_tool("viewfactors grid.obj -o grid2.csv --sky-exact") == 2);
    CHECK(strstr(test_read_text(test_path("stderr.txt")),
                 "--sky-exact: applies to --sky-view-factor FILE only") != NULL);
    CHECK(!test_file_exists(test_path("grid2.csv")));
}

/* A floor (unit square, z = 0, up) under a grid of CROWD x CROWD squares at z = 0.15, each
 * 0.6 of its cell: 800 triangles. Seen from the floor, the sky tiles above break into more
 * than SHADOW_MAX_PIECES visible pieces at some points, so with --sky-exact those tiles are
 * clipped on their second try, with room for more pieces (before it, 96 of 128 were
 * sampled, leaving the floor's bound at 0.011). Against the test's own count of cosine rays
 * from the floor that cross z = 0.15 between the squares. */
enum { CROWD = 20 };

static double monte_carlo_crowd(uint32_t rays, double *sigma)
{
    rad_rng rng = rad_rng_seed(23, 0, 0);
    uint32_t escaped = 0;
    for (uint32_t r = 0; r < rays; r++) {
        double x = rad_rng_uniform(&rng), y = rad_rng_uniform(&rng);
        double u = rad_rng_uniform(&rng), phi = 2 * pi * rad_rng_uniform(&rng);
        double radius = sqrt(u), up = sqrt(1 - u);
        double cx = x + 0.15 * radius * cos(phi) / up, cy = y + 0.15 * radius * sin(phi) / up;
        bool blocked = false;
        if (cx >= 0 && cx < 1 && cy >= 0 && cy < 1) {
            double fx = cx * CROWD - floor(cx * CROWD), fy = cy * CROWD - floor(cy * CROWD);
            blocked = fx >= 0.2 && fx <= 0.8 && fy >= 0.2 && fy <= 0.8;
        }
        escaped += !blocked;
    }
    double p = (double)escaped / rays;
    *sigma = sqrt(p * (1 - p) / rays);
    return p;
}

static void check_crowded_sky(void)
{
    quad_count = 0;
    add_quad("floor", 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0);
    for (int i = 0; i < CROWD; i++)
        for (int j = 0; j < CROWD; j++) {
            double x0 = (i + 0.2) / CROWD, y0 = (j + 0.2) / CROWD, x1 = (i + 0.8) / CROWD,
                   y1 = (j + 0.8) / CROWD, z = 0.15;
            add_quad(i + j ? NULL : "grid", x0, y0, z, x1, y0, z, x1, y1, z, x0, y1, z);
        }
    write_obj("crowd.obj");
    CHECK(run("viewfactors crowd.obj -o crowd.csv --sky-view-factor crowd-sky.csv --sky-exact "
              "--stats crowd.json"));
    const char *stats = test_read_text(test_path("crowd.json"));
    CHECK(strstr(stats, "\"sky_sampled_pairs\": 0,") != NULL);
    CHECK(strstr(stats, "\"sky_short_surfaces\": 0,") != NULL);
    int index;
    double svf = NAN, bound = NAN, sigma;
    CHECK(sky_row(test_read_text(test_path("crowd-sky.csv")), "floor", &index, &svf, &bound));
    double reference = monte_carlo_crowd(1u << 22, &sigma);
    printf("floor under %d x %d squares, --sky-exact: SVF %.6f (bound %.2g), Monte Carlo %.6f "
           "+- %.2g\n",
           CROWD, CROWD, svf, bound, reference, sigma);
    CHECK(bound <= 1e-4);
    CHECK(fabs(svf - reference) <= 4 * sigma + bound);
}

static void check_plate(void)
{
    quad_count = 0;
    add_quad("plate", 0, 0, 0, 2, 0, 0, 2, 1, 0, 0, 1, 0);
    write_obj("plate.obj");
    CHECK(run("viewfactors plate.obj -o plate.csv --sky-view-factor plate-sky.csv"));
    int index;
    double svf = NAN, bound = NAN;
    CHECK(sky_row(test_read_text(test_path("plate-sky.csv")), "plate", &index, &svf, &bound));
    printf("flat plate: SVF %.12f (bound %.2g)\n", svf, bound);
    CHECK_NEAR(svf, 1, 1e-9);
    CHECK(bound <= 1e-9);
}

/* The unit cube, faces inward: no face sees any sky. */
static void check_closed_box(void)
{
    quad_count = 0;
    add_quad("bottom", 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0);
    add_quad("top", 0, 0, 1, 0, 1, 1, 1, 1, 1, 1, 0, 1);
    add_quad("front", 0, 0, 0, 0, 0, 1, 1, 0, 1, 1, 0, 0);
    add_quad("back", 0, 1, 0, 1, 1, 0, 1, 1, 1, 0, 1, 1);
    add_quad("left", 0, 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1);
    add_quad("right", 1, 0, 0, 1, 0, 1, 1, 1, 1, 1, 1, 0);
    write_obj("box.obj");
    CHECK(run("viewfactors box.obj -o box.csv --sky-view-factor box-sky.csv --threads 1"));
    char sky[4096];
    snprintf(sky, sizeof(sky), "%s", test_read_text(test_path("box-sky.csv")));
    const char *names[6] = {"bottom", "top", "front", "back", "left", "right"};
    for (int k = 0; k < 6; k++) {
        int index;
        double svf = NAN, bound = NAN;
        CHECK(sky_row(sky, names[k], &index, &svf, &bound) && index == k + 1);
        printf("closed box: %s SVF %.3g (bound %.2g)\n", names[k], svf, bound);
        CHECK(svf >= 0 && svf <= 1e-4);
        CHECK_NEAR(row_sum(test_read_text(test_path("box.csv")), names[k]) + svf, 1, 1e-4);
    }
    /* the same bytes with 2 threads */
    CHECK(run("viewfactors box.obj -o box2.csv --sky-view-factor box-sky2.csv --threads 2"));
    CHECK(strcmp(sky, test_read_text(test_path("box-sky2.csv"))) == 0);
}

/* Several mesh files and an obstruction: the obstruction has no row, the indices follow
 * the matrix's; a .mtx name gets the Matrix Market column. */
static void check_layouts(void)
{
    quad_count = 0;
    add_quad("ground", 0, 0, 0, 4, 0, 0, 4, 4, 0, 0, 4, 0);
    write_obj("ground.obj");
    quad_count = 0;
    add_quad("roof", 1, 1, 2, 3, 1, 2, 3, 3, 2, 1, 3, 2); /* facing up */
    write_obj("roof.obj");
    quad_count = 0;
    add_quad("canopy", 1, 1, 1, 1, 3, 1, 3, 3, 1, 3, 1, 1); /* facing down, blocks only */
    write_obj("canopy.obj");
    CHECK(run("viewfactors ground.obj roof.obj --obstruction canopy.obj -o g.mtx "
              "--sky-view-factor g-sky.mtx"));
    const char *mtx = test_read_text(test_path("g-sky.mtx"));
    CHECK(strncmp(mtx, "%%MatrixMarket matrix array real general\n", 41) == 0);
    CHECK(strstr(mtx, "% sky 1 ") && strstr(mtx, " ground\n"));
    CHECK(strstr(mtx, "% sky 2 ") && strstr(mtx, " roof\n"));
    CHECK(!strstr(mtx, "canopy"));
    const char *size = strstr(mtx, "\n2 1\n");
    CHECK(size != NULL);
    double ground = NAN, roof = NAN;
    if (size)
        CHECK(sscanf(size + 5, "%lf %lf", &ground, &roof) == 2);
    /* the roof is flat and open: 1; the ground loses what the canopy (2 x 2 at height 1,
     * centred over it) and the roof's underside cover */
    CHECK_NEAR(roof, 1, 1e-9);
    CHECK(ground > 0.5 && ground < 1);
    /* the same numbers in CSV */
    CHECK(run("viewfactors ground.obj roof.obj --obstruction canopy.obj -o g.csv "
              "--sky-view-factor g-sky.csv"));
    int index;
    double svf = NAN, bound = NAN;
    CHECK(sky_row(test_read_text(test_path("g-sky.csv")), "roof", &index, &svf, &bound) &&
          index == 2);
    CHECK(sky_row(test_read_text(test_path("g-sky.csv")), "ground", &index, &svf, &bound) &&
          index == 1);
    CHECK_NEAR(svf, ground, 1e-8);
    /* an unwritable sky file is refused before any work, and nothing is written */
    CHECK(test_run_tool("viewfactors ground.obj -o g3.csv --sky-view-factor "
                        "no-such-folder/sky.csv") != 0);
    CHECK(!test_file_exists(test_path("g3.csv")));
}

int main(void)
{
    test_tmpdir();
    check_canyon(1, 1, 20);
    check_canyon(1, 2, 20);
    check_canyon(1, 1, 100);
    check_canyon_with_beam();
    check_sampled_sky();
    check_crowded_sky();
    check_plate();
    check_closed_box();
    check_layouts();
    return test_finish("test_sky_viewfactor");
}
