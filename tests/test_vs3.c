/*
 * test_vs3.c - the View3D input reader (rad_scene_load_vs3) and the multi-file scene
 * (rad_scene_load_files): surfaces, areas, flags and emissivities computed by hand from
 * the geometry written here; every refused input names its line.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "testlib.h"

static const char cube_vs3[] =
    "T A simple cube\n"
    "C encl=1 list=3 eps = 2e-5 maxU=10\n"
    "F 3\n"
    "!  #   x    y    z      coordinates of vertices\n"
    "V  1   0.   0.   0.\n"
    "V  2   1.   0.   0.\n"
    "V  3   1.   1.   0.\n"
    "V  4   0.   1.   0.\n"
    "V  5   0.   0.   1.\n"
    "V  6   1.   0.   1.\n"
    "V  7   1.   1.   1.\n"
    "V  8   0.   1.   1.\n"
    "!  #   v1  v2  v3  v4 base cmb  emit  name      surface data\n"
    "S  1    1   2   3   4   0   0   0.50  zeq0\n"
    "S  2    1   4   8   5   0   0   0.50  xeq0\n"
    "S  3    1   5   6   2   0   0   0.50  yeq0\n"
    "s  4    7   6   5   8   0   0   0.50  zeq1   ! a trailing comment\n"
    "S  5    7   3   2   6   0   0   0.50  xeq1\n"
    "S  6    7   8   4   3   0   0   0.50  yeq1\n"
    "End of data\n"
    "S  7    this is not read\n";

static int find_surface(const rad_scene *scene, const char *name)
{
    for (uint32_t s = 0; s < scene->surface_count; s++)
        if (strcmp(scene->surfaces[s].name, name) == 0)
            return (int)s;
    return -1;
}

static double surface_area(const rad_scene *scene, const char *name)
{
    int s = find_surface(scene, name);
    if (s < 0)
        return -1;
    double area = 0;
    const rad_surface *surface = &scene->surfaces[s];
    for (uint32_t t = surface->first_triangle; t < surface->first_triangle + surface->triangle_count;
         t++) {
        const uint32_t *v = scene->triangles[t].vertex;
        rad_vec3 a = scene->positions[v[0]], b = scene->positions[v[1]], c = scene->positions[v[2]];
        double e0[3] = {b.x - a.x, b.y - a.y, b.z - a.z}, e1[3] = {c.x - a.x, c.y - a.y, c.z - a.z};
        double n[3] = {e0[1] * e1[2] - e0[2] * e1[1], e0[2] * e1[0] - e0[0] * e1[2],
                       e0[0] * e1[1] - e0[1] * e1[0]};
        area += 0.5 * sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    }
    return area;
}

/* The mean front normal of a surface (area-weighted). */
static rad_vec3 surface_normal(const rad_scene *scene, const char *name)
{
    int s = find_surface(scene, name);
    rad_vec3 sum = {0, 0, 0};
    if (s < 0)
        return sum;
    const rad_surface *surface = &scene->surfaces[s];
    for (uint32_t t = surface->first_triangle; t < surface->first_triangle + surface->triangle_count;
         t++) {
        const uint32_t *v = scene->triangles[t].vertex;
        rad_vec3 a = scene->positions[v[0]], b = scene->positions[v[1]], c = scene->positions[v[2]];
        double e0[3] = {b.x - a.x, b.y - a.y, b.z - a.z}, e1[3] = {c.x - a.x, c.y - a.y, c.z - a.z};
        sum.x += 0.5 * (e0[1] * e1[2] - e0[2] * e1[1]);
        sum.y += 0.5 * (e0[2] * e1[0] - e0[0] * e1[2]);
        sum.z += 0.5 * (e0[0] * e1[1] - e0[1] * e1[0]);
    }
    return sum;
}

static void test_cube(void)
{
    rad_scene *scene = NULL;
    rad_vs3_control control;
    rad_error error = {0};
    const char *path = test_write_file("cube.vs3", cube_vs3);
    CHECK(rad_scene_load_vs3(path, NULL, &scene, &control, &error) == RAD_OK);
    if (!scene) {
        fprintf(stderr, "%s\n", error.message);
        return;
    }
    CHECK(scene->surface_count == 6);
    CHECK(strcmp(control.title, "A simple cube") == 0);
    CHECK(control.enclosure && !control.emit);
    CHECK_NEAR(control.eps, 2e-5, 1e-12);
    CHECK(control.max_u == 10 && control.max_o == 8 && control.list == 3);
    const char *names[6] = {"zeq0", "xeq0", "yeq0", "zeq1", "xeq1", "yeq1"};
    /* outward-facing right-hand normals in View3D's example point INTO the cube */
    const double inward[6][3] = {{0, 0, 1}, {1, 0, 0}, {0, 1, 0}, {0, 0, -1}, {-1, 0, 0}, {0, -1, 0}};
    for (int s = 0; s < 6; s++) {
        CHECK(strcmp(scene->surfaces[s].name, names[s]) == 0);
        CHECK_NEAR(surface_area(scene, names[s]), 1.0, 1e-12);
        CHECK_NEAR(scene->surfaces[s].emissivity, 0.5, 1e-12);
        CHECK(scene->surfaces[s].flags == 0);
        rad_vec3 n = surface_normal(scene, names[s]);
        CHECK_NEAR(n.x * inward[s][0] + n.y * inward[s][1] + n.z * inward[s][2], 1.0, 1e-12);
    }
    rad_scene_destroy(scene);

    /* rad_scene_load recognises the content whatever the file is called */
    CHECK(rad_scene_is_vs3(path));
    path = test_write_file("cube-input.txt", cube_vs3);
    CHECK(rad_scene_is_vs3(path));
    CHECK(!rad_scene_is_vs3(test_write_file("plain.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")));
    CHECK(!rad_scene_is_vs3(test_write_file("faces.obj", "o a\nv 0 0 0\nv 1 0 0\nv 0 1 0\n"
                                                         "v 0 0 1\nf 3 2 1\nf 3 4 1\n")));
    CHECK(!rad_scene_is_vs3(test_write_file("titled.obj", "T x\nv 0 0 0\nf 3 1 2\n")));
    CHECK(!rad_scene_is_vs3(test_path("missing.vs3")));
    CHECK(rad_scene_load(path, NULL, &scene, &error) == RAD_OK);
    CHECK(scene && scene->surface_count == 6);
    rad_scene_destroy(scene);
}

/* Pinney & Bean test 4 (View3D's manual): an L-shaped room of 3 m height, with floor and
 * ceiling given as three rectangles each, combined. */
static void test_combined_and_triangles(void)
{
    const char *text =
        "T L-shaped room\n"
        "C encl=1 emit=1\n"
        "F 3\n"
        "V  1   0.   3.   3.\nV  2   1.   3.   3.\nV  3   0.   3.   0.\nV  4   1.   3.   0.\n"
        "V  5   0.   1.   0.\nV  6   1.   1.   0.\nV  7   3.   1.   0.\nV  8   0.   0.   0.\n"
        "V  9   1.   0.   0.\nV 10   3.   0.   0.\nV 11   0.   0.   3.\nV 12   1.   0.   3.\n"
        "V 13   3.   0.   3.\nV 14   0.   1.   3.\nV 15   1.   1.   3.\nV 16   3.   1.   3.\n"
        "S  1   11  13  10   8   0   0   0.90  srf-1\n"
        "S  2   10  13  16   7   0   0   0.90  srf-2\n"
        "S  3    6   7  16  15   0   0   0.90  srf-3\n"
        "S  4    4   6  15   2   0   0   0.90  srf-4\n"
        "S  5    3   4   2   1   0   0   0.90  srf-5\n"
        "S  6    8   3   1  11   0   0   0.90  srf-6\n"
        "S  7   11  14  15  12   0   0   0.50  srf-7\n"
        "S  8    8   9   6   5   0   0   0.90  srf-8\n"
        "S  9    1   2  15  14   0   7   0.80  srf-7b    ! surfaces that combine\n"
        "S 10   15  16  13  12   0   7   0.20  srf-7c\n"
        "S 11    5   6   4   3   0   8   0.90  srf-8b\n"
        "S 12    9  10   7   6   0   8   0.90  srf-8c\n"
        "S 13    9  10   7   0   0   0   0.70\n" /* a triangle, no name */
        "End of data\n";
    rad_scene *scene = NULL;
    rad_vs3_control control;
    rad_error error = {0};
    CHECK(rad_scene_load_vs3(test_write_file("room.vs3", text), NULL, &scene, &control, &error) ==
          RAD_OK);
    if (!scene) {
        fprintf(stderr, "%s\n", error.message);
        return;
    }
    CHECK(control.enclosure && control.emit);
    CHECK(scene->surface_count == 9); /* 12 polygons, 4 combined away, one triangle */
    CHECK(find_surface(scene, "srf-7b") < 0 && find_surface(scene, "srf-8c") < 0);
    /* ceiling: 1x1 + 1x2 + 2x1 = 5 m2; emissivity area-weighted */
    CHECK_NEAR(surface_area(scene, "srf-7"), 5.0, 1e-12);
    CHECK_NEAR(surface_area(scene, "srf-8"), 5.0, 1e-12);
    CHECK_NEAR(scene->surfaces[find_surface(scene, "srf-7")].emissivity,
               (1 * 0.5 + 2 * 0.8 + 2 * 0.2) / 5, 1e-12);
    CHECK_NEAR(surface_area(scene, "srf-1"), 9.0, 1e-12);
    CHECK_NEAR(surface_area(scene, "13"), 0.5 * 2 * 1, 1e-12);
    CHECK_NEAR(scene->surfaces[find_surface(scene, "13")].emissivity, 0.7, 1e-12);
    rad_scene_destroy(scene);
}

/* A 3 x 3 wall with a window (subsurface), a door-sized null surface and an obstruction. */
static void test_subsurfaces(void)
{
    const char *text =
        "F 3\n"
        "V 1 0 0 0\nV 2 3 0 0\nV 3 3 0 3\nV 4 0 0 3\n"              /* wall, facing -y */
        "V 5 0.5 0 1\nV 6 1.5 0 1\nV 7 1.5 0 2\nV 8 0.5 0 2\n"      /* window 1 x 1 */
        "V 9 2 0 0\nV 10 2.5 0 0\nV 11 2.5 0 2\nV 12 2 0 2\n"       /* null 0.5 x 2 at the edge */
        "V 13 0 -1 0\nV 14 3 -1 0\nV 15 3 -1 1\nV 16 0 -1 1\n"
        "S 1 1 2 3 4 0 0 0.9 wall\n"
        "S 2 5 6 7 8 1 0 0.3 window\n"
        "N 3 12 11 10 9 1 0 0.9 gap\n"
        "O 4 13 14 15 16 0 0 0.9 screen\n";
    rad_scene *scene = NULL;
    rad_error error = {0};
    CHECK(rad_scene_load_vs3(test_write_file("wall.vs3", text), NULL, &scene, NULL, &error) ==
          RAD_OK);
    if (!scene) {
        fprintf(stderr, "%s\n", error.message);
        return;
    }
    CHECK(scene->surface_count == 4);
    CHECK_NEAR(surface_area(scene, "wall"), 9.0 - 1.0 - 1.0, 1e-12);
    rad_vec3 n = surface_normal(scene, "wall"); /* still one plane, facing -y */
    CHECK_NEAR(n.y, -7.0, 1e-12);
    CHECK_ABS(n.x, 0, 1e-12);
    CHECK_ABS(n.z, 0, 1e-12);
    CHECK_NEAR(surface_area(scene, "window"), 1.0, 1e-12);
    CHECK_NEAR(surface_area(scene, "gap"), 1.0, 1e-12);
    CHECK(scene->surfaces[find_surface(scene, "gap")].flags == RAD_SURFACE_OBSTRUCTION);
    CHECK(scene->surfaces[find_surface(scene, "screen")].flags == RAD_SURFACE_OBSTRUCTION);
    CHECK(scene->surfaces[find_surface(scene, "window")].flags == 0);
    CHECK(scene->surfaces[find_surface(scene, "wall")].flags == 0);
    /* no triangle of the wall overlaps the window: none has its centroid inside it */
    const rad_surface *wall = &scene->surfaces[find_surface(scene, "wall")];
    int inside = 0;
    for (uint32_t t = wall->first_triangle; t < wall->first_triangle + wall->triangle_count; t++) {
        const uint32_t *v = scene->triangles[t].vertex;
        double x = (scene->positions[v[0]].x + scene->positions[v[1]].x + scene->positions[v[2]].x) / 3;
        double z = (scene->positions[v[0]].z + scene->positions[v[1]].z + scene->positions[v[2]].z) / 3;
        inside += (x > 0.5 && x < 1.5 && z > 1 && z < 2) || (x > 2 && x < 2.5 && z < 2);
    }
    CHECK(inside == 0);
    rad_scene_destroy(scene);
}

/* Loads `body` (vertex lines of a unit square and more) and expects `status` with
 * ":line:" and `words` in the message. */
static void expect_error(const char *body, rad_status status, int line, const char *words)
{
    rad_scene *scene = NULL;
    rad_error error = {0};
    const char *path = test_write_file("bad.vs3", body);
    rad_status got = rad_scene_load_vs3(path, NULL, &scene, NULL, &error);
    CHECK(got == status);
    CHECK(scene == NULL);
    char where[64];
    snprintf(where, sizeof(where), "bad.vs3:%d: ", line);
    if (!strstr(error.message, where) || !strstr(error.message, words)) {
        test_fail(__FILE__, __LINE__, "expected '%s' and '%s' in: %s", where, words,
                  error.message);
    }
    rad_scene_destroy(scene);
}

#define SQUARE "F 3\nV 1 0 0 0\nV 2 1 0 0\nV 3 1 1 0\nV 4 0 1 0\n"

static void test_errors(void)
{
    expect_error(SQUARE "S 1 1 2 3 9 0 0 0.9 a\n", RAD_ERR_PARSE, 6, "undefined vertex 9");
    expect_error(SQUARE "V 5 1 1 0.5\nS 1 1 2 5 4 0 0 0.9 a\n", RAD_ERR_PARSE, 7, "not planar");
    expect_error(SQUARE "V 5 0.4 0.4 0\nS 1 1 2 5 4 0 0 0.9 a\n", RAD_ERR_PARSE, 7,
                 "not convex");
    expect_error(SQUARE "V 5 2 0 0\nS 1 1 2 5 0 0 0 0.9 a\n", RAD_ERR_PARSE, 7, "zero area");
    expect_error(SQUARE "S 1 1 2 3 0 0 0 0.9 a\nS 2 1 3 4 0 0 0 0.9 a\n", RAD_ERR_PARSE, 7,
                 "name 'a' is used twice");
    expect_error(SQUARE "S 1 1 2 3 0 0 0 0.9 a\nS 1 1 3 4 0 0 0 0.9 b\n", RAD_ERR_PARSE, 7,
                 "surface 1 is already defined on line 6");
    expect_error(SQUARE "V 2 5 5 5\n", RAD_ERR_PARSE, 6, "vertex 2 is already defined on line 3");
    expect_error(SQUARE "S 1 1 2 3 4 0 0 1.5 a\n", RAD_ERR_PARSE, 6, "emissivity");
    expect_error(SQUARE "S 1 1 2 3 4 0 0 0.9 a\nM 2 1 2 3 4 1 0 0.9 m\n", RAD_ERR_PARSE, 7,
                 "must face opposite to its base surface 1");
    expect_error(SQUARE "M 1 1 2 3 4 0 0 0.9 m\n", RAD_ERR_PARSE, 6,
                 "mask surface 1 needs a base");
    expect_error("F 3a\n", RAD_ERR_UNSUPPORTED, 1, "F 3a");
    expect_error(SQUARE "S 1 1 2 3 4 0 0 0.9 a\nS 2 1 2 3 0 5 0 0.9 b\n", RAD_ERR_PARSE, 7,
                 "base 5 is not a surface defined before it");
    expect_error(SQUARE "V 5 0 0 1\nV 6 1 0 1\nS 1 1 2 3 4 0 0 0.9 a\nS 2 1 2 6 5 1 0 0.9 b\n",
                 RAD_ERR_PARSE, 9, "plane of its base");
    expect_error(SQUARE "V 5 2 0 0\nV 6 2 1 0\nS 1 1 2 3 4 0 0 0.9 a\nS 2 2 5 6 3 1 0 0.9 b\n",
                 RAD_ERR_PARSE, 9, "not inside its base");
    expect_error(SQUARE "S 1 1 2 3\n", RAD_ERR_PARSE, 6, "expected 'S number");
    expect_error(SQUARE "C encl=2\n", RAD_ERR_PARSE, 6, "encl must be 0 or 1");
    expect_error(SQUARE "Q 1 2\n", RAD_ERR_PARSE, 6, "not a View3D line");
}

/* What a base and the surfaces cut out of it may be, and what they may not: cut out of
 * a cut-out (each keeps what the next does not cover); covering the base entirely (the
 * base would have no area: refused), overlapping each other (the overlap would count
 * twice: refused, naming both and their lines) or touching along an edge (fine); a
 * number or coordinate out of range (refused as such, not as "zero area"). */
static void test_subsurface_checks(void)
{
    const char *nested = "F 3\nV 1 0 0 0\nV 2 3 0 0\nV 3 3 3 0\nV 4 0 3 0\n"
                         "V 5 0.5 0.5 0\nV 6 2.5 0.5 0\nV 7 2.5 2.5 0\nV 8 0.5 2.5 0\n"
                         "V 9 1 1 0\nV 10 2 1 0\nV 11 2 2 0\nV 12 1 2 0\n"
                         "S 1 1 2 3 4 0 0 0.9 wall\n"
                         "S 2 5 6 7 8 1 0 0.9 frame\n"
                         "S 3 9 10 11 12 2 0 0.9 pane\n";
    rad_scene *scene = NULL;
    rad_error error = {0};
    CHECK(rad_scene_load_vs3(test_write_file("nested.vs3", nested), NULL, &scene, NULL,
                             &error) == RAD_OK);
    if (scene) {
        CHECK_NEAR(surface_area(scene, "wall"), 9.0 - 4.0, 1e-12);
        CHECK_NEAR(surface_area(scene, "frame"), 4.0 - 1.0, 1e-12);
        CHECK_NEAR(surface_area(scene, "pane"), 1.0, 1e-12);
    } else {
        fprintf(stderr, "%s\n", error.message);
    }
    rad_scene_destroy(scene);
    /* two halves touching along x = 0.5: no overlap, the base keeps nothing but is not
     * covered by one; so one of them is a triangle, and the base keeps a quarter */
    const char *touching = SQUARE "V 5 0.5 0 0\nV 6 0.5 1 0\n"
                                  "S 1 1 2 3 4 0 0 0.9 a\nS 2 1 5 6 4 1 0 0.9 left\n"
                                  "S 3 5 2 3 0 1 0 0.9 right\n";
    scene = NULL;
    CHECK(rad_scene_load_vs3(test_write_file("touching.vs3", touching), NULL, &scene, NULL,
                             &error) == RAD_OK);
    if (scene) {
        CHECK_NEAR(surface_area(scene, "a"), 0.25, 1e-12);
        CHECK_NEAR(surface_area(scene, "left"), 0.5, 1e-12);
        CHECK_NEAR(surface_area(scene, "right"), 0.25, 1e-12);
    }
    rad_scene_destroy(scene);

    expect_error(SQUARE "S 1 1 2 3 4 0 0 0.9 a\nS 2 1 2 3 4 1 0 0.9 b\n", RAD_ERR_PARSE, 6,
                 "surface 1 'a' is covered entirely by what is cut out of it (surface 2 'b', "
                 "line 7): nothing of it would be left to have view factors");
    /* covered by a subsurface and a null surface together */
    expect_error(SQUARE "V 5 0.5 0 0\nV 6 0.5 1 0\nS 1 1 2 3 4 0 0 0.9 a\n"
                        "S 2 1 5 6 4 1 0 0.9 b\nN 3 5 6 3 2 1 0 0.9 c\n",
                 RAD_ERR_PARSE, 8,
                 "surface 1 'a' is covered entirely by what is cut out of it (surface 2 'b', "
                 "line 9, and more)");
    /* a mask covering its base */
    expect_error(SQUARE "S 1 1 2 3 4 0 0 0.9 a\nM 2 4 3 2 1 1 0 0.9 m\n", RAD_ERR_PARSE, 6,
                 "surface 1 'a' is covered entirely");
    expect_error(SQUARE "V 5 0.6 0 0\nV 6 0.6 1 0\nV 7 0.4 0 0\nV 8 0.4 1 0\n"
                        "S 1 1 2 3 4 0 0 0.9 a\nS 2 1 5 6 4 1 0 0.9 left\n"
                        "S 3 7 2 3 8 1 0 0.9 right\n",
                 RAD_ERR_PARSE, 12,
                 "surface 3 'right' overlaps surface 2 'left' (line 11) by area 0.2, both cut "
                 "out of base surface 1: the overlap would be counted twice");
    /* a null surface inside a subsurface's place: overlap too */
    expect_error(SQUARE "V 5 0.25 0.25 0\nV 6 0.75 0.25 0\nV 7 0.75 0.75 0\nV 8 0.25 0.75 0\n"
                        "S 1 1 2 3 4 0 0 0.9 a\nS 2 5 6 7 8 1 0 0.9 window\n"
                        "N 3 8 7 6 5 1 0 0.9 hole\n",
                 RAD_ERR_PARSE, 12, "surface 3 'hole' overlaps surface 2 'window' (line 11)");
    /* the class around them: outside, not coplanar, reversed, base after it or itself */
    expect_error(SQUARE "V 5 0.5 0.5 0\nV 6 1.5 0.5 0\nV 7 1.5 1.5 0\nS 1 1 2 3 4 0 0 0.9 a\n"
                        "S 2 5 6 7 0 1 0 0.9 b\n",
                 RAD_ERR_PARSE, 10, "surface 2 is not inside its base surface 1");
    expect_error(SQUARE "V 5 0.2 0.2 0.1\nV 6 0.8 0.2 0.1\nV 7 0.8 0.8 0.1\n"
                        "S 1 1 2 3 4 0 0 0.9 a\nS 2 5 6 7 0 1 0 0.9 b\n",
                 RAD_ERR_PARSE, 10, "surface 2 is not in the plane of its base surface 1");
    expect_error(SQUARE "V 5 0.2 0.2 0\nV 6 0.8 0.2 0\nV 7 0.8 0.8 0\n"
                        "S 1 1 2 3 4 0 0 0.9 a\nS 2 7 6 5 0 1 0 0.9 b\n",
                 RAD_ERR_PARSE, 10, "surface 2 must face the same way as its base surface 1");
    expect_error(SQUARE "S 1 1 2 3 4 1 0 0.9 a\n", RAD_ERR_PARSE, 6,
                 "surface 1: base 1 is not a surface defined before it");
    expect_error(SQUARE "S 1 1 2 3 0 2 0 0.9 a\nS 2 1 3 4 0 0 0 0.9 b\n", RAD_ERR_PARSE, 6,
                 "surface 1: base 2 is not a surface defined before it");
    /* numbers and coordinates out of range */
    expect_error(SQUARE "V 4294967294 1 1 1\n", RAD_ERR_UNSUPPORTED, 6,
                 "vertex number 4294967294 is larger than this reader supports (16777216)");
    expect_error(SQUARE "V 99999999999999999999 1 1 1\n", RAD_ERR_UNSUPPORTED, 6,
                 "vertex number 99999999999999999999 is larger than this reader supports");
    expect_error(SQUARE "S 16777217 1 2 3 4 0 0 0.9 a\n", RAD_ERR_UNSUPPORTED, 6,
                 "surface number 16777217 is larger than this reader supports (16777216)");
    expect_error(SQUARE "S 1 1 2 3 99999999999 0 0 0.9 a\n", RAD_ERR_PARSE, 6,
                 "surface 1: vertex 99999999999 is not a vertex of the file (numbers go up to "
                 "16777216)");
    expect_error(SQUARE "S 1 1 2 3 4 0 0 0.9 a\nS 2 1 2 3 0 1 18446744073709551616 0.9 b\n",
                 RAD_ERR_PARSE, 7,
                 "surface 2: cmb 18446744073709551616 is not a surface of the file");
    expect_error(SQUARE "C maxU=99999999999\n", RAD_ERR_PARSE, 6,
                 "maxU must be at most 4294967294, not '99999999999'");
    expect_error("F 3\nV 1 0 0 0\nV 2 1e308 0 0\nV 3 1e308 1e308 0\nV 4 0 1e308 0\n"
                 "S 1 1 2 3 4 0 0 0.9 a\n",
                 RAD_ERR_PARSE, 3,
                 "vertex 2: coordinate 1e308 is out of the supported range (magnitude at most "
                 "3.40282e+38)");
    expect_error(SQUARE "V 5 -1e39 0 0\n", RAD_ERR_PARSE, 6, "coordinate -1e39 is out of the");
    expect_error(SQUARE "V 5 1e400 0 0\n", RAD_ERR_PARSE, 6, "finite coordinates");
    /* an underflowing coordinate is the double nearest it (about 0) */
    scene = NULL;
    CHECK(rad_scene_load_vs3(test_write_file("tiny.vs3", "F 3\nV 1 1e-400 0 0\nV 2 1 0 0\n"
                                                         "V 3 1 1 0\nS 1 1 2 3 0 0 0 0.9 t\n"),
                             NULL, &scene, NULL, &error) == RAD_OK);
    if (scene)
        CHECK_NEAR(surface_area(scene, "t"), 0.5, 1e-12);
    rad_scene_destroy(scene);
}

static void test_files(void)
{
    test_write_file("north.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n");
    test_write_file("south.obj", "o part1\nv 0 0 1\nv 1 1 1\nv 1 0 1\nf 1 2 3\n"
                                 "o part2\nv 0 0 1\nv 0 1 1\nv 1 1 1\nf 1 2 3\n");
    char command[4300];
    snprintf(command, sizeof(command), "mkdir -p '%s/other'", test_tmpdir());
    CHECK(system(command) == 0);
    test_write_file("other/north.stl", "solid x\nendsolid x\n");
    rad_scene_file files[2] = {{test_path("north.obj"), 0, false},
                               {test_path("south.obj"), RAD_SURFACE_OBSTRUCTION, false}};
    rad_scene *scene = NULL;
    rad_error error = {0};
    CHECK(rad_scene_load_files(files, 2, NULL, &scene, &error) == RAD_OK);
    if (!scene) {
        fprintf(stderr, "%s\n", error.message);
        return;
    }
    CHECK(scene->surface_count == 2);
    CHECK(strcmp(scene->surfaces[0].name, "north") == 0);
    CHECK(strcmp(scene->surfaces[1].name, "south") == 0);
    CHECK(scene->surfaces[0].flags == 0);
    CHECK(scene->surfaces[1].flags == RAD_SURFACE_OBSTRUCTION);
    CHECK_NEAR(surface_area(scene, "south"), 1.0, 1e-12);
    CHECK_NEAR(scene->surfaces[0].emissivity, 0.9, 1e-12);
    CHECK(rad_scene_set_surface_flags(scene, "north", RAD_SURFACE_TWO_SIDED, &error) == RAD_OK);
    CHECK(scene->surfaces[0].flags == RAD_SURFACE_TWO_SIDED);
    CHECK(rad_scene_set_surface_flags(scene, "west", RAD_SURFACE_TWO_SIDED, &error) ==
          RAD_ERR_INVALID);
    CHECK(strstr(error.message, "no surface or material 'west' in ") != NULL);
    rad_scene_destroy(scene);

    rad_scene_file same[2] = {{test_path("north.obj"), 0, false},
                              {test_path("other/north.stl"), 0, false}};
    scene = NULL;
    CHECK(rad_scene_load_files(same, 2, NULL, &scene, &error) == RAD_ERR_INVALID);
    CHECK(scene == NULL);
    CHECK(strstr(error.message, "surface name 'north' is also used") != NULL);

    /* a .vs3 among the files becomes one surface too, with its area-weighted emissivity */
    test_write_file("box.vs3", cube_vs3);
    rad_scene_file mixed[2] = {{test_path("north.obj"), 0, false}, {test_path("box.vs3"), 0, false}};
    CHECK(rad_scene_load_files(mixed, 2, NULL, &scene, &error) == RAD_OK);
    CHECK(scene && scene->surface_count == 2);
    if (scene) {
        CHECK_NEAR(surface_area(scene, "box"), 6.0, 1e-12);
        CHECK_NEAR(scene->surfaces[find_surface(scene, "box")].emissivity, 0.5, 1e-12);
    }
    rad_scene_destroy(scene);

    /* a file kept whole: its own surfaces; an obstruction file beside it */
    rad_scene_file kept[2] = {{test_path("south.obj"), 0, true},
                              {test_path("north.obj"), RAD_SURFACE_OBSTRUCTION, false}};
    CHECK(rad_scene_load_files(kept, 2, NULL, &scene, &error) == RAD_OK);
    CHECK(scene && scene->surface_count == 3);
    if (scene) {
        CHECK_NEAR(surface_area(scene, "part1"), 0.5, 1e-12);
        CHECK_NEAR(surface_area(scene, "part2"), 0.5, 1e-12);
        CHECK(scene->surfaces[find_surface(scene, "north")].flags == RAD_SURFACE_OBSTRUCTION);
        CHECK(scene->surfaces[find_surface(scene, "part1")].flags == 0);
    }
    rad_scene_destroy(scene);
}

/* A 2 x 2 floor with a 1 x 1 mask lying on it, facing it, under a 2 x 2 ceiling: the
 * mask's factors are set after the computation (here a matrix made by hand). */
static void test_masks(void)
{
    const char *text = "F 3\nV 1 0 0 0\nV 2 2 0 0\nV 3 2 2 0\nV 4 0 2 0\n"
                       "V 5 0 0 1\nV 6 2 0 1\nV 7 2 2 1\nV 8 0 2 1\n"
                       "V 9 0.5 0.5 0\nV 10 1.5 0.5 0\nV 11 1.5 1.5 0\nV 12 0.5 1.5 0\n"
                       "S 1 1 2 3 4 0 0 0.9 floor\n"
                       "M 2 12 11 10 9 1 0 0.4 rug\n"
                       "S 3 5 8 7 6 0 0 0.9 ceiling\n";
    const char *path = test_write_file("masked.vs3", text);
    rad_scene *scene = NULL;
    rad_error error = {0};
    CHECK(rad_scene_load_vs3(path, NULL, &scene, NULL, &error) == RAD_OK);
    if (!scene) {
        fprintf(stderr, "%s\n", error.message);
        return;
    }
    CHECK(scene->surface_count == 3);
    CHECK_NEAR(surface_area(scene, "floor"), 3.0, 1e-12); /* the mask is cut out */
    CHECK_NEAR(surface_area(scene, "rug"), 1.0, 1e-12);
    CHECK(scene->surfaces[1].flags == RAD_SURFACE_OBSTRUCTION);
    rad_viewfactor_matrix *m = NULL;
    CHECK(rad_viewfactor_matrix_create(3, 2, &m, &error) == RAD_OK);
    if (!m) {
        rad_scene_destroy(scene);
        return;
    }
    m->area[0] = 3;
    m->area[2] = 4;
    m->row_start[0] = 0;
    m->row_start[1] = 1;
    m->row_start[2] = 1;
    m->row_start[3] = 2;
    m->column[0] = 2;
    m->value[0] = 0.3;
    m->error_bound[0] = 4e-5;
    m->column[1] = 0;
    m->value[1] = 0.3 * 3 / 4;
    CHECK(rad_viewfactor_matrix_apply_vs3_masks(path, scene, &m, &error) == RAD_OK);
    CHECK(scene->surfaces[1].flags == 0);
    CHECK(m->n == 3 && m->row_start[3] == 4);
    CHECK_NEAR(m->area[0], 4.0, 1e-12);
    CHECK_NEAR(m->area[1], 1.0, 1e-12);
    CHECK_NEAR(m->area[2], 4.0, 1e-12);
    CHECK_NEAR(rad_viewfactor_matrix_get(m, 0, 2), 0.3 * 3 / 4, 1e-12);
    CHECK_NEAR(m->error_bound[1], 4e-5 * 3 / 4, 1e-12);
    CHECK_NEAR(rad_viewfactor_matrix_get(m, 0, 1), 1.0 / 4, 1e-12);
    CHECK_NEAR(rad_viewfactor_matrix_get(m, 1, 0), 1.0, 1e-12);
    CHECK(rad_viewfactor_matrix_get(m, 1, 2) == 0 && rad_viewfactor_matrix_get(m, 2, 1) == 0);
    CHECK_NEAR(rad_viewfactor_matrix_get(m, 2, 0), 0.3 * 3 / 4, 1e-12);
    for (uint32_t I = 0; I < 3; I++) /* reciprocity */
        for (uint32_t J = 0; J < 3; J++)
            CHECK_NEAR(m->area[I] * rad_viewfactor_matrix_get(m, I, J),
                       m->area[J] * rad_viewfactor_matrix_get(m, J, I), 1e-12);
    rad_viewfactor_matrix_destroy(m);
    rad_scene_destroy(scene);
}

int main(void)
{
    test_masks();
    test_cube();
    test_combined_and_triangles();
    test_subsurfaces();
    test_errors();
    test_subsurface_checks();
    test_files();
    return test_finish("test_vs3");
}
