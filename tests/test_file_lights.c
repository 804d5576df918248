/*
 * test_file_lights.c - lights read from scene files: glTF KHR_lights_punctual placed by
 * their nodes' transforms (TRS and matrix, a parent's scale and rotation), colour x
 * intensity, cone angles converted to degrees, names and defaults, the range warning, the
 * malformed cases refused with RAD_ERR_PARSE naming the file; a Collada file's point, spot
 * and directional lights through Assimp (full cone angles halved, an ambient light
 * skipped, the units warning once); and `radiosity info` listing each light.
 *
 * Every expected position and direction is worked out by hand in the comments.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "testlib.h"

#define PI 3.14159265358979323846

/* Warnings the loader sends, kept for inspection. */
typedef struct warning_log {
    char text[8192];
    int count;
} warning_log;

static void keep_warning(void *user, const char *message)
{
    warning_log *log = user;
    size_t n = strlen(log->text);
    snprintf(log->text + n, sizeof(log->text) - n, "%s\n", message);
    log->count++;
}

static int occurrences(const char *text, const char *what)
{
    int count = 0;
    for (const char *p = strstr(text, what); p; p = strstr(p + 1, what))
        count++;
    return count;
}

/* A 10 x 10 floor quad in the y = 0 plane as the buffer `bin_name` beside the glTF: four
 * float positions then six uint16 indices (60 bytes). */
static void write_floor_buffer(const char *bin_name)
{
    static const float corners[12] = {-5, 0, -5, 5, 0, -5, 5, 0, 5, -5, 0, 5};
    static const uint16_t indices[6] = {0, 2, 1, 0, 3, 2};
    FILE *file = fopen(test_path(bin_name), "wb");
    if (!file) {
        test_fail(__FILE__, __LINE__, "cannot write %s", bin_name);
        return;
    }
    fwrite(corners, sizeof(corners[0]), 12, file);
    fwrite(indices, sizeof(indices[0]), 6, file);
    fclose(file);
}

/* A glTF file whose mesh 0 is the floor (in floor.bin); `nodes`, `lights` and `scenes` are
 * JSON array bodies, node 0 being the floor's node. */
static const char *write_light_gltf(const char *name, const char *nodes, const char *lights,
                                    const char *scenes)
{
    static char json[16384];
    snprintf(json, sizeof(json),
             "{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"KHR_lights_punctual\"],"
             "\"scene\":0,\"scenes\":[%s],\"nodes\":[%s],"
             "\"extensions\":{\"KHR_lights_punctual\":{\"lights\":[%s]}},"
             "\"meshes\":[{\"name\":\"floor\",\"primitives\":[{\"attributes\":{\"POSITION\":0},"
             "\"indices\":1}]}],"
             "\"buffers\":[{\"byteLength\":60,\"uri\":\"floor.bin\"}],"
             "\"bufferViews\":[{\"buffer\":0,\"byteLength\":48},"
             "{\"buffer\":0,\"byteOffset\":48,\"byteLength\":12}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":4,"
             "\"type\":\"VEC3\",\"min\":[-5,0,-5],\"max\":[5,0,5]},"
             "{\"bufferView\":1,\"componentType\":5123,\"count\":6,\"type\":\"SCALAR\"}]}",
             scenes, nodes, lights);
    return test_write_file(name, json);
}

static rad_scene *load(const char *path, warning_log *log, rad_error *error)
{
    rad_load_options options = {keep_warning, log};
    rad_scene *scene = NULL;
    memset(error, 0, sizeof(*error));
    if (rad_scene_load(path, &options, &scene, error) != RAD_OK) {
        rad_scene_destroy(scene);
        return NULL;
    }
    return scene;
}

static const rad_light *light_named(const rad_scene *scene, const char *name)
{
    for (uint32_t l = 0; l < scene->light_count; l++)
        if (strcmp(scene->lights[l].name, name) == 0)
            return &scene->lights[l];
    test_fail(__FILE__, __LINE__, "no light named '%s'", name);
    return NULL;
}

static void check_vec(rad_vec3 got, double x, double y, double z, double tolerance)
{
    CHECK_ABS(got.x, x, tolerance);
    CHECK_ABS(got.y, y, tolerance);
    CHECK_ABS(got.z, z, tolerance);
}

/* The nodes of the good file:
 * 0 floor.
 * 1 "rig": translation (10,0,0), rotation q = (0.5,0.5,0.5,0.5) (120 degrees about
 *   (1,1,1): x -> y, y -> z, z -> x, so R (a,b,c) = (c,a,b)), scale 2; child 2.
 * 2 "lampnode": translation (1,2,3), light 0 (point "bulb", intensity 100).
 *   position = T R S (1,2,3) = (10,0,0) + R (2,4,6) = (10,0,0) + (6,2,4) = (16,2,4);
 *   direction = R S (0,0,-1) = R (0,0,-2) = (-2,0,0) -> (-1,0,0).
 * 3 "spotnode": matrix = rotation -90 degrees about x with translation (0,3,0), column-major
 *   columns (1,0,0,0) (0,0,-1,0) (0,1,0,0) (0,3,0,1); light 1 (spot without a name,
 *   colour (1,0.5,0.25), intensity 40, cones 0.2 / 0.5 rad, a range).
 *   position (0,3,0); direction = -(third column) = (0,-1,0).
 * 4 "sunnode": rotation -90 degrees about x, q = (-sin 45, 0, 0, cos 45); light 2
 *   (directional "sun", colour (1,0.9,0.8), 1000 lux). -Z turns to (0,-1,0).
 * 5 unnamed node, light 3 (point, no name, defaults: colour 1, intensity 1) -> "light 3".
 * 6 a node of scene 1 only (not the default scene) holding light 0: not read.
 * Light 4 (a spot with the default cones 0 / pi/4) is referenced by no node: not read. */
static const char good_nodes[] =
    "{\"mesh\":0,\"name\":\"floor\"},"
    "{\"name\":\"rig\",\"translation\":[10,0,0],\"rotation\":[0.5,0.5,0.5,0.5],"
    "\"scale\":[2,2,2],\"children\":[2]},"
    "{\"name\":\"lampnode\",\"translation\":[1,2,3],"
    "\"extensions\":{\"KHR_lights_punctual\":{\"light\":0}}},"
    "{\"name\":\"spotnode\",\"matrix\":[1,0,0,0, 0,0,-1,0, 0,1,0,0, 0,3,0,1],"
    "\"extensions\":{\"KHR_lights_punctual\":{\"light\":1}}},"
    "{\"name\":\"sunnode\",\"rotation\":[-0.70710678118654752,0,0,0.70710678118654752],"
    "\"extensions\":{\"KHR_lights_punctual\":{\"light\":2}}},"
    "{\"extensions\":{\"KHR_lights_punctual\":{\"light\":3}}},"
    "{\"name\":\"elsewhere\",\"extensions\":{\"KHR_lights_punctual\":{\"light\":0}}}";
static const char good_lights[] =
    "{\"type\":\"point\",\"name\":\"bulb\",\"intensity\":100},"
    "{\"type\":\"spot\",\"color\":[1,0.5,0.25],\"intensity\":40,\"range\":12,"
    "\"spot\":{\"innerConeAngle\":0.2,\"outerConeAngle\":0.5}},"
    "{\"type\":\"directional\",\"name\":\"sun\",\"color\":[1,0.9,0.8],\"intensity\":1000},"
    "{\"type\":\"point\"},"
    "{\"type\":\"spot\",\"name\":\"unused\"}";
static const char good_scenes[] = "{\"nodes\":[0,1,3,4,5]},{\"nodes\":[6]}";

static void gltf_lights(void)
{
    write_floor_buffer("floor.bin");
    const char *path = write_light_gltf("lights.gltf", good_nodes, good_lights, good_scenes);
    warning_log log = {{0}, 0};
    rad_error error;
    rad_scene *scene = load(path, &log, &error);
    if (!scene) {
        test_fail(__FILE__, __LINE__, "lights.gltf: %s", error.message);
        return;
    }
    CHECK_NEAR(scene->unit_metres, 1, 0);
    CHECK(scene->light_count == 4);
    const rad_light *bulb = light_named(scene, "bulb");
    if (bulb) {
        CHECK(bulb->type == RAD_LIGHT_POINT);
        check_vec(bulb->position, 16, 2, 4, 1e-9);
        check_vec(bulb->direction, -1, 0, 0, 1e-9);
        CHECK_NEAR(bulb->intensity.r, 100, 1e-12);
        CHECK_NEAR(bulb->intensity.b, 100, 1e-12);
    }
    /* an unnamed light takes its node's name */
    const rad_light *spot = light_named(scene, "spotnode");
    if (spot) {
        CHECK(spot->type == RAD_LIGHT_SPOT);
        check_vec(spot->position, 0, 3, 0, 1e-12);
        check_vec(spot->direction, 0, -1, 0, 1e-12);
        /* 0.2 rad = 11.4592 degrees, 0.5 rad = 28.6479 degrees */
        CHECK_NEAR(spot->inner_degrees, 0.2 * 180 / PI, 1e-12);
        CHECK_NEAR(spot->outer_degrees, 0.5 * 180 / PI, 1e-12);
        CHECK_ABS(spot->inner_degrees, 11.459, 5e-4);
        CHECK_ABS(spot->outer_degrees, 28.648, 5e-4);
        CHECK_NEAR(spot->intensity.r, 40, 1e-12);
        CHECK_NEAR(spot->intensity.g, 20, 1e-12);
        CHECK_NEAR(spot->intensity.b, 10, 1e-12);
    }
    const rad_light *sun = light_named(scene, "sun");
    if (sun) {
        CHECK(sun->type == RAD_LIGHT_DIRECTIONAL);
        check_vec(sun->direction, 0, -1, 0, 1e-9);
        CHECK_NEAR(sun->intensity.r, 1000, 1e-12);
        CHECK_NEAR(sun->intensity.g, 900, 1e-12);
        CHECK_NEAR(sun->intensity.b, 800, 1e-12);
        CHECK_NEAR(sun->angular_diameter_degrees, 0, 0);
    }
    /* neither the light nor its node has a name: its index */
    const rad_light *plain = light_named(scene, "light 3");
    if (plain) {
        CHECK(plain->type == RAD_LIGHT_POINT);
        check_vec(plain->position, 0, 0, 0, 0);
        CHECK_NEAR(plain->intensity.g, 1, 0);
    }
    /* the range: one warning naming the light */
    CHECK(occurrences(log.text, "range") == 1);
    CHECK(strstr(log.text, "spotnode") != NULL);
    rad_scene_destroy(scene);
}

/* Malformed lights: RAD_ERR_PARSE, the file named, and the JSON path or value at fault. */
static void gltf_refusals(void)
{
    static const struct {
        const char *file, *nodes, *lights, *names;
    } cases[] = {
        {"index.gltf",
         "{\"mesh\":0},{\"extensions\":{\"KHR_lights_punctual\":{\"light\":2}}}",
         "{\"type\":\"point\"},{\"type\":\"point\"}",
         "nodes[1].extensions.KHR_lights_punctual.light"},
        {"fraction.gltf",
         "{\"mesh\":0},{\"extensions\":{\"KHR_lights_punctual\":{\"light\":0.5}}}",
         "{\"type\":\"point\"},{\"type\":\"point\"}",
         "nodes[1].extensions.KHR_lights_punctual.light"},
        {"nolights.gltf",
         "{\"mesh\":0},{\"extensions\":{\"KHR_lights_punctual\":{\"light\":0}}}", "",
         "nodes[1].extensions.KHR_lights_punctual.light"},
        {"type.gltf", "{\"mesh\":0},{\"extensions\":{\"KHR_lights_punctual\":{\"light\":1}}}",
         "{\"type\":\"point\"},{\"type\":\"area\"}", "lights[1].type 'area'"},
        {"notype.gltf", "{\"mesh\":0},{}", "{\"intensity\":3}", "lights[0].type"},
        {"negative.gltf", "{\"mesh\":0},{\"extensions\":{\"KHR_lights_punctual\":{\"light\":0}}}",
         "{\"type\":\"point\",\"intensity\":-1}", "lights[0].intensity"},
        {"colour.gltf", "{\"mesh\":0},{\"extensions\":{\"KHR_lights_punctual\":{\"light\":0}}}",
         "{\"type\":\"point\",\"color\":[1,-0.5,1]}", "lights[0].color"},
        {"inner.gltf", "{\"mesh\":0},{\"extensions\":{\"KHR_lights_punctual\":{\"light\":0}}}",
         "{\"type\":\"spot\",\"spot\":{\"innerConeAngle\":0.6,\"outerConeAngle\":0.5}}",
         "lights[0].spot"},
        {"outer.gltf", "{\"mesh\":0},{\"extensions\":{\"KHR_lights_punctual\":{\"light\":0}}}",
         "{\"type\":\"spot\",\"spot\":{\"innerConeAngle\":0.1,\"outerConeAngle\":1.6}}",
         "lights[0].spot"},
        {"flat.gltf",
         "{\"mesh\":0},{\"matrix\":[1,0,0,0, 0,1,0,0, 0,0,0,0, 0,0,0,1],\"extensions\":"
         "{\"KHR_lights_punctual\":{\"light\":0}}}",
         "{\"type\":\"directional\"}", "nodes[1]"},
        {"matrix16.gltf",
         "{\"mesh\":0},{\"matrix\":[1,0,0],\"extensions\":{\"KHR_lights_punctual\":"
         "{\"light\":0}}}",
         "{\"type\":\"point\"}", "nodes[1].matrix"},
    };
    for (size_t k = 0; k < sizeof(cases) / sizeof(cases[0]); k++) {
        const char *path =
            write_light_gltf(cases[k].file, cases[k].nodes, cases[k].lights, "{\"nodes\":[0,1]}");
        warning_log log = {{0}, 0};
        rad_error error;
        rad_scene *scene = load(path, &log, &error);
        bool ok = !scene && error.status == RAD_ERR_PARSE &&
                  strstr(error.message, cases[k].file) && strstr(error.message, cases[k].names);
        if (!ok)
            test_fail(__FILE__, __LINE__, "%s: status %d, message '%s'", cases[k].file,
                      (int)error.status, error.message);
        CHECK(ok);
        CHECK(strchr(error.message, '\n') == NULL);
        rad_scene_destroy(scene);
    }
}

/* A Collada file (Y up, metres) with a floor and, under transformed nodes:
 * - "lampnode" (translate (1,2,3)) under "rig" (translate (0,1,0), scale 2): a point
 *   light, colour (10,20,30): position (0,1,0) + 2 (1,2,3) = (2,5,6);
 * - "spotnode" (translate (0,4,0), rotate -60 degrees about x): a spot, colour (5,6,7),
 *   falloff_angle 40 and penumbra_angle 20 degrees: Assimp's full cones 40 and 60, so
 *   half-angles 20 and 30; direction R_x(-60) (0,0,-1) = (0, sin -60, -cos -60) =
 *   (0, -0.8660254, -0.5);
 * - "widenode": a spot whose full outer cone is 170 + 30 = 200 degrees: clamped to a
 *   hemisphere (90), its inner 85;
 * - "sunnode" (rotate -90 degrees about x): directional, colour (1000,900,800): (0,-1,0);
 * - "ambnode": an ambient light, skipped with a warning. */
static const char collada[] =
    "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n"
    "<COLLADA xmlns=\"http://www.collada.org/2005/11/COLLADASchema\" version=\"1.4.1\">\n"
    " <asset><unit name=\"meter\" meter=\"1\"/><up_axis>Y_UP</up_axis></asset>\n"
    " <library_lights>\n"
    "  <light id=\"lamp\"><technique_common><point><color>10 20 30</color></point>"
    "</technique_common></light>\n"
    "  <light id=\"spot\"><technique_common><spot><color>5 6 7</color>"
    "<falloff_angle>40</falloff_angle></spot></technique_common>"
    "<extra><technique profile=\"FCOLLADA\"><penumbra_angle>20</penumbra_angle></technique>"
    "</extra></light>\n"
    "  <light id=\"wide\"><technique_common><spot><color>1 1 1</color>"
    "<falloff_angle>170</falloff_angle></spot></technique_common>"
    "<extra><technique profile=\"FCOLLADA\"><penumbra_angle>30</penumbra_angle></technique>"
    "</extra></light>\n"
    "  <light id=\"sun\"><technique_common><directional><color>1000 900 800</color>"
    "</directional></technique_common></light>\n"
    "  <light id=\"amb\"><technique_common><ambient><color>1 1 1</color></ambient>"
    "</technique_common></light>\n"
    " </library_lights>\n"
    " <library_geometries><geometry id=\"quad\" name=\"floor\"><mesh>\n"
    "  <source id=\"quad-pos\"><float_array id=\"quad-pos-array\" count=\"12\">"
    "-5 0 -5 5 0 -5 5 0 5 -5 0 5</float_array><technique_common>"
    "<accessor source=\"#quad-pos-array\" count=\"4\" stride=\"3\"><param name=\"X\" "
    "type=\"float\"/><param name=\"Y\" type=\"float\"/><param name=\"Z\" type=\"float\"/>"
    "</accessor></technique_common></source>\n"
    "  <vertices id=\"quad-vtx\"><input semantic=\"POSITION\" source=\"#quad-pos\"/></vertices>\n"
    "  <triangles count=\"2\"><input semantic=\"VERTEX\" source=\"#quad-vtx\" offset=\"0\"/>"
    "<p>0 3 2 0 2 1</p></triangles>\n"
    " </mesh></geometry></library_geometries>\n"
    " <library_visual_scenes><visual_scene id=\"scene\">\n"
    "  <node id=\"floor\" name=\"floor\"><instance_geometry url=\"#quad\"/></node>\n"
    "  <node id=\"rig\" name=\"rig\"><translate>0 1 0</translate><scale>2 2 2</scale>\n"
    "   <node id=\"lampnode\" name=\"lampnode\"><translate>1 2 3</translate>"
    "<instance_light url=\"#lamp\"/></node>\n"
    "  </node>\n"
    "  <node id=\"spotnode\" name=\"spotnode\"><translate>0 4 0</translate>"
    "<rotate>1 0 0 -60</rotate><instance_light url=\"#spot\"/></node>\n"
    "  <node id=\"widenode\" name=\"widenode\"><instance_light url=\"#wide\"/></node>\n"
    "  <node id=\"sunnode\" name=\"sunnode\"><rotate>1 0 0 -90</rotate>"
    "<instance_light url=\"#sun\"/></node>\n"
    "  <node id=\"ambnode\" name=\"ambnode\"><instance_light url=\"#amb\"/></node>\n"
    " </visual_scene></library_visual_scenes>\n"
    " <scene><instance_visual_scene url=\"#scene\"/></scene>\n"
    "</COLLADA>\n";

static void collada_lights(void)
{
    const char *path = test_write_file("lights.dae", collada);
    warning_log log = {{0}, 0};
    rad_error error;
    rad_scene *scene = load(path, &log, &error);
    if (!scene) {
        test_fail(__FILE__, __LINE__, "lights.dae: %s", error.message);
        return;
    }
    CHECK(scene->light_count == 4);
    const rad_light *lamp = light_named(scene, "lampnode");
    if (lamp) {
        CHECK(lamp->type == RAD_LIGHT_POINT);
        check_vec(lamp->position, 2, 5, 6, 1e-5);
        CHECK_NEAR(lamp->intensity.r, 10, 1e-6);
        CHECK_NEAR(lamp->intensity.g, 20, 1e-6);
        CHECK_NEAR(lamp->intensity.b, 30, 1e-6);
    }
    const rad_light *spot = light_named(scene, "spotnode");
    if (spot) {
        CHECK(spot->type == RAD_LIGHT_SPOT);
        check_vec(spot->position, 0, 4, 0, 1e-5);
        check_vec(spot->direction, 0, -sqrt(3) / 2, -0.5, 1e-6);
        CHECK_NEAR(spot->inner_degrees, 20, 1e-5);
        CHECK_NEAR(spot->outer_degrees, 30, 1e-5);
        CHECK_NEAR(spot->intensity.g, 6, 1e-6);
    }
    const rad_light *wide = light_named(scene, "widenode");
    if (wide) {
        CHECK_NEAR(wide->outer_degrees, 90, 0);
        CHECK_NEAR(wide->inner_degrees, 85, 1e-5);
    }
    const rad_light *sun = light_named(scene, "sunnode");
    if (sun) {
        CHECK(sun->type == RAD_LIGHT_DIRECTIONAL);
        check_vec(sun->direction, 0, -1, 0, 1e-6);
        CHECK_NEAR(sun->intensity.r, 1000, 1e-6);
        CHECK_NEAR(sun->intensity.b, 800, 1e-6);
    }
    CHECK(occurrences(log.text, "'ambnode' is an ambient light") == 1);
    CHECK(occurrences(log.text, "'widenode'") == 1);
    CHECK(occurrences(log.text, "not photometric") == 1);
    rad_scene_destroy(scene);
}

/* `radiosity info` lists each light on its own line. */
static void info_lists_lights(void)
{
    int code = test_run_tool("info lights.gltf");
    const char *out = test_read_text(test_path("stdout.txt"));
    CHECK(code == 0);
    CHECK(strstr(out, "lights: 4\n") != NULL);
    static const char *gltf_lines[] = {
        "  point       bulb                      position (16, 2, 4)  intensity (100, 100, "
        "100) cd\n",
        "  spot        spotnode                  position (0, 3, 0)  direction (0, -1, 0)  "
        "intensity (40, 20, 10) cd  cone 11.459 to 28.648 degrees from the axis\n",
        "  sun         sun                       direction (0, -1, 0)  intensity (1000, 900, "
        "800) lux\n",
        "  point       light 3                   position (0, 0, 0)  intensity (1, 1, 1) cd\n",
    };
    for (size_t k = 0; k < sizeof(gltf_lines) / sizeof(gltf_lines[0]); k++)
        if (!strstr(out, gltf_lines[k]))
            test_fail(__FILE__, __LINE__, "info lights.gltf lacks the line:\n%sin:\n%s",
                      gltf_lines[k], out);
    code = test_run_tool("info lights.dae");
    out = test_read_text(test_path("stdout.txt"));
    CHECK(code == 0);
    CHECK(strstr(out, "lights: 4\n") != NULL);
    CHECK(strstr(out, "  spot        spotnode                  position (0, 4, 0)  direction "
                      "(0, -0.866025, -0.5)  intensity (5, 6, 7) cd  cone 20 to 30 degrees "
                      "from the axis\n") != NULL);
    CHECK(strstr(out, "  sun         sunnode                   direction (0, -1, 0)  "
                      "intensity (1000, 900, 800) lux\n") != NULL);
}

int main(void)
{
    test_tmpdir();
    gltf_lights();
    gltf_refusals();
    collada_lights();
    info_lists_lights();
    return test_finish("test_file_lights");
}
