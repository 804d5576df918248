/*
 * test_obj_input.c - the OBJ pre-check of rad_scene_load: face indices at and beyond the
 * limits of a 64-bit integer (INT64_MIN has no positive counterpart), in each of the
 * v/vt/vn lists; number forms Assimp 5.2 misreads or reads (".5", "-.5", "1e05", "1E-3",
 * "+2"); several libraries on one mtllib line, a library name with spaces, a library
 * found by its base name beside the OBJ; lines Assimp would take without a word (a vertex
 * of two numbers) or refuse in its own words. Every number expected is worked out by hand
 * from the geometry written here; every message is the exact text.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "testlib.h"

static char warnings[4096];

static void keep_warning(void *user, const char *message)
{
    (void)user;
    size_t n = strlen(warnings);
    snprintf(warnings + n, sizeof(warnings) - n, "%s\n", message);
}

/* Loads `name` written with `text`; NULL with the message in *error on failure. */
static rad_scene *load(const char *name, const char *text, rad_error *error)
{
    warnings[0] = 0;
    rad_load_options options = {keep_warning, NULL};
    rad_scene *scene = NULL;
    memset(error, 0, sizeof(*error));
    if (rad_scene_load(test_write_file(name, text), &options, &scene, error) != RAD_OK)
        return NULL;
    return scene;
}

/* `text` is refused with exactly "TMP/name:" + `message`. */
static void expect_refused(const char *name, const char *text, const char *message)
{
    rad_error error;
    rad_scene *scene = load(name, text, &error);
    char expected[1024];
    snprintf(expected, sizeof(expected), "%s%s", test_path(name), message);
    if (scene || strcmp(error.message, expected) != 0)
        test_fail(__FILE__, __LINE__, "%s: expected '%s', got '%s'", name, expected,
                  scene ? "(loaded)" : error.message);
    rad_scene_destroy(scene);
}

static double total_area(const rad_scene *scene)
{
    double area = 0;
    for (uint32_t t = 0; t < scene->triangle_count; t++) {
        const uint32_t *v = scene->triangles[t].vertex;
        rad_vec3 a = scene->positions[v[0]], b = scene->positions[v[1]], c = scene->positions[v[2]];
        double e[3] = {b.x - a.x, b.y - a.y, b.z - a.z}, f[3] = {c.x - a.x, c.y - a.y, c.z - a.z};
        double n[3] = {e[1] * f[2] - e[2] * f[1], e[2] * f[0] - e[0] * f[2],
                       e[0] * f[1] - e[1] * f[0]};
        area += 0.5 * sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    }
    return area;
}

static const rad_material *material_named(const rad_scene *scene, const char *name)
{
    for (uint32_t m = 0; m < scene->material_count; m++)
        if (strcmp(scene->materials[m].name, name) == 0)
            return &scene->materials[m];
    return NULL;
}

#define TRIANGLE "v 0 0 0\nv 1 0 0\nv 0 1 0\n"

/* Face indices at the limits: INT64_MIN (negating it is undefined behaviour), one below
 * it and above INT64_MAX (out of range for strtoll), INT64_MAX, in each list. */
static void test_extreme_indices(void)
{
    expect_refused("min.obj", TRIANGLE "f 1 2 -9223372036854775808\n",
                   ":4: face refers to vertex -9223372036854775808 (counting back) but only 3 "
                   "are defined above it");
    expect_refused("below-min.obj", TRIANGLE "f 1 2 -9223372036854775809\n",
                   ":4: face refers to vertex -9223372036854775809 (counting back) but only 3 "
                   "are defined above it");
    expect_refused("max.obj", TRIANGLE "f 1 2 9223372036854775807\n",
                   ":4: face refers to vertex 9223372036854775807 but only 3 are defined");
    expect_refused("above-max.obj", TRIANGLE "f 1 2 99999999999999999999999\n",
                   ":4: face refers to vertex 99999999999999999999999, beyond any file's count");
    expect_refused("uv-min.obj", TRIANGLE "vt 0 0\nf 1/1 2/1 3/-9223372036854775808\n",
                   ":5: face refers to texture coordinate -9223372036854775808 (counting back) "
                   "but only 1 is defined above it");
    expect_refused("normal-min.obj", TRIANGLE "vn 0 0 1\nf 1//1 2//1 3//-9223372036854775808\n",
                   ":5: face refers to normal -9223372036854775808 (counting back) but only 1 "
                   "is defined above it");
    /* vt beyond its list: Assimp 5.2 only asserts this (a read out of bounds in release) */
    expect_refused("uv-beyond.obj", TRIANGLE "vt 0 0\nf 1/1 2/5 3/1\n",
                   ":5: face refers to texture coordinate 5 but only 1 is defined");
    expect_refused("normal-beyond.obj", TRIANGLE "vn 0 0 1\nvn 0 0 1\nf 1//1 2//3 3//1\n",
                   ":6: face refers to normal 3 but only 2 are defined");
    expect_refused("zero-uv.obj", TRIANGLE "vt 0 0\nf 1/1 2/0 3/1\n",
                   ":5: face refers to texture coordinate 0: OBJ indices start at 1");
    expect_refused("word.obj", TRIANGLE "f 1 2 x3\n",
                   ":4: face corner 'x3' is not v, v/vt, v//vn or v/vt/vn with whole-number "
                   "indices");
    expect_refused("float-index.obj", TRIANGLE "f 1 2 3.0\n",
                   ":4: face corner '3.0' is not v, v/vt, v//vn or v/vt/vn with whole-number "
                   "indices");
}

/* ".5", "-.5", "1e05", "1E-3", "+2", "+.5": one triangle of base 1 and height 2 (area 1),
 * one of legs 1e5 and 1e-3 (area 50, as floats), one of legs 0.5 and 0.5 (area 0.125). */
static void test_number_forms(void)
{
    rad_error error;
    rad_scene *scene = load("numbers.obj",
                            "v -.5 0 0\nv .5 0 0\nv 0 +2 0\n"
                            "v 0 0 5\nv 1e05 0 5\nv 0 1E-3 5\n"
                            "v 0 0 9\nv +.5 0 9\nv 0 0.5e0 9\n"
                            "vt .5 .5\nf 1/1 2/1 3/1\nf 4 5 6\nf 7 8 9\n",
                            &error);
    CHECK(scene != NULL);
    if (!scene) {
        fprintf(stderr, "%s\n", error.message);
        return;
    }
    CHECK(scene->triangle_count == 3);
    /* Assimp keeps single precision: 1E-3 is the float nearest it */
    CHECK_NEAR(total_area(scene), 1 + 0.5 * 1e5 * (double)1e-3f + 0.125, 1e-12);
    CHECK(warnings[0] == 0);
    rad_scene_destroy(scene);
}

/* Lines Assimp 5.2 takes without a word (a vertex of two numbers: it reads on into the
 * next line) or refuses in its own words. */
static void test_short_lines(void)
{
    expect_refused("two.obj", "v 0 0 0\nv 1 0\nv 0 1 0\nf 1 2 3\n",
                   ":2: 'v' line with 2 numbers, 3 expected");
    expect_refused("w0.obj", "v 0 0 0 1\nv 1 0 0 0\nv 0 1 0 1\nf 1 2 3\n",
                   ":2: vertex weight w is 0");
    expect_refused("vt1.obj", TRIANGLE "vt 0.5\nf 1/1 2/1 3/1\n",
                   ":4: 'vt' line with 1 number, 2 expected");
    expect_refused("vn2.obj", TRIANGLE "vn 1 0\nf 1//1 2//1 3//1\n",
                   ":4: 'vn' line with 2 numbers, 3 expected");
    expect_refused("huge.obj", "v 0 0 0\nv 1e39 0 0\nv 0 1 0\nf 1 2 3\n",
                   ":2: v coordinate 1e+39 is beyond single precision");
    expect_refused("nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n",
                   ":2: v coordinate is not a finite number");
}

/* mtllib: several files (Assimp 5.2 looks up "red.mtl blue.mtl" as one name), a name
 * with spaces, a path that is not there but whose base name is beside the OBJ (Assimp
 * finds it too; the check had refused it: now a warning), and neither (an error naming
 * the OBJ, its line and the missing file). */
static void test_material_libraries(void)
{
    test_write_file("red.mtl", "newmtl red\nKd 0.75 0 0\n");
    test_write_file("blue.mtl", "newmtl blue\nKd 0 0 0.25\n");
    test_write_file("green paint.mtl", "newmtl green\nKd 0 0.5 0\n");
    const char *faces = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
                        "usemtl red\nf 1 2 3\nusemtl blue\nf 1 3 4\n";
    char text[512];
    snprintf(text, sizeof(text), "mtllib red.mtl blue.mtl\n%s", faces);
    rad_error error;
    rad_scene *scene = load("two-libraries.obj", text, &error);
    CHECK(scene != NULL);
    if (scene) {
        const rad_material *red = material_named(scene, "red");
        const rad_material *blue = material_named(scene, "blue");
        CHECK(red && red->albedo.r == 0.75f && red->albedo.g == 0 && red->albedo.b == 0);
        CHECK(blue && blue->albedo.b == 0.25f && blue->albedo.r == 0);
        CHECK(warnings[0] == 0);
    } else {
        fprintf(stderr, "%s\n", error.message);
    }
    rad_scene_destroy(scene);

    scene = load("spaced.obj", "mtllib green paint.mtl\n" TRIANGLE "usemtl green\nf 1 2 3\n",
                 &error);
    CHECK(scene != NULL);
    if (scene) {
        const rad_material *green = material_named(scene, "green");
        CHECK(green && green->albedo.g == 0.5f && green->albedo.r == 0);
    }
    rad_scene_destroy(scene);

    snprintf(text, sizeof(text), "# exported elsewhere\nmtllib scenes/red.mtl\n%s", faces);
    scene = load("moved.obj", text, &error);
    CHECK(scene != NULL);
    if (scene) {
        const rad_material *red = material_named(scene, "red");
        CHECK(red && red->albedo.r == 0.75f);
        char expected[1024];
        snprintf(expected, sizeof(expected),
                 "%s:2: material library 'scenes/red.mtl' not found; 'red.mtl' beside the OBJ "
                 "is read instead\n",
                 test_path("moved.obj"));
        CHECK(strstr(warnings, expected) != NULL);
        if (!strstr(warnings, expected))
            fprintf(stderr, "warnings: %s\n", warnings);
    }
    rad_scene_destroy(scene);

    snprintf(text, sizeof(text), "mtllib red.mtl\nmtllib scenes/x.mtl\n%s", faces);
    expect_refused("lost.obj", text,
                   ":2: material library 'scenes/x.mtl' not found (nor 'x.mtl' beside the OBJ)");
    snprintf(text, sizeof(text), "mtllib red.mtl gone.mtl\n%s", faces);
    expect_refused("one-lost.obj", text, ":1: material library 'gone.mtl' not found");
}

/* What Assimp 5.2 reads and the checks must not refuse: an empty last slot ("1/"), a
 * line continued by a trailing backslash; and what it refuses that is harmless: a comment
 * after a face (Assimp reads the copy without it). */
static void test_assimp_leniency(void)
{
    rad_error error;
    rad_scene *scene = load("slash.obj", TRIANGLE "f 1/ 2/ 3/\n", &error);
    CHECK(scene && scene->triangle_count == 1);
    rad_scene_destroy(scene);
    /* the face is on line 4, continued on 5; the bad one on line 7 (6 continued) */
    scene = load("continued.obj", TRIANGLE "f 1 2 \\\n 3\n", &error);
    CHECK(scene && scene->triangle_count == 1);
    rad_scene_destroy(scene);
    /* a comment after a face's corners (Assimp 5.2 refuses it: "Invalid face index") */
    scene = load("comment.obj", TRIANGLE "f 1 2 3 # the floor\n", &error);
    CHECK(scene != NULL && scene->triangle_count == 1);
    rad_scene_destroy(scene);
    expect_refused("continued-bad.obj", TRIANGLE "f 1 2 \\\n 3\nf 1 \\\n 2 7\n",
                   ":6: face refers to vertex 7 but only 3 are defined");
}

/* A usemtl no library defines: Assimp 5.2 makes up a grey 0.6 material without a word;
 * here, the documented default albedo under the material's own name and a warning at its
 * first use, wherever the library line is (a usemtl may come before its mtllib). */
static void test_undefined_material(void)
{
    rad_error error;
    rad_scene *scene = load("typo.obj",
                            "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nusemtl red\nf 1 2 3\n"
                            "mtllib red.mtl\nusemtl bleu\nf 1 3 4\nusemtl bleu\nf 1 4 2\n",
                            &error);
    CHECK(scene != NULL);
    if (!scene)
        return;
    const rad_material *red = material_named(scene, "red"), *typo = material_named(scene, "bleu");
    CHECK(red && red->albedo.r == 0.75f);
    CHECK(typo && typo->albedo.r == (float)RAD_DEFAULT_ALBEDO &&
          typo->albedo.g == (float)RAD_DEFAULT_ALBEDO && typo->emission.r == 0);
    char expected[1024];
    snprintf(expected, sizeof(expected),
             "%s:8: usemtl 'bleu': no material library of the file defines it; its faces get "
             "the default albedo 0.5\n",
             test_path("typo.obj"));
    if (strcmp(warnings, expected) != 0)
        test_fail(__FILE__, __LINE__, "expected the warning '%s', got '%s'", expected, warnings);
    rad_scene_destroy(scene);
}

/* What Assimp still refuses after the checks: named by the file, in our words first. */
static void test_assimp_words(void)
{
    expect_refused("empty.obj", "",
                   ": cannot read the scene: the file is empty or too short to hold a scene "
                   "(Assimp: OBJ-file is too small.)");
    rad_error error;
    rad_scene *scene = load("prose.txt", "Dear diary, no scene today.\n", &error);
    char expected[1024];
    snprintf(expected, sizeof(expected),
             "%s: cannot read the scene: not a scene format Assimp reads (Assimp: No suitable "
             "reader found for the file format of file \"%s\".)",
             test_path("prose.txt"), test_path("prose.txt"));
    CHECK(scene == NULL);
    if (strcmp(error.message, expected) != 0)
        test_fail(__FILE__, __LINE__, "expected '%s', got '%s'", expected, error.message);
    rad_scene_destroy(scene);
}

int main(void)
{
    test_tmpdir();
    test_extreme_indices();
    test_number_forms();
    test_short_lines();
    test_material_libraries();
    test_assimp_leniency();
    test_undefined_material();
    test_assimp_words();
    return test_finish("test_obj_input");
}
