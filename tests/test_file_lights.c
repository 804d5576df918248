/*
 * test_file_lights.c - lights read from scene files: glTF KHR_lights_punctual placed by
 * their nodes' transforms (TRS and matrix, a parent's scale and rotation), colour x
 * intensity, cone angles converted to degrees, names and defaults, the range warning, the
 * malformed cases refused with RAD_ERR_PARSE naming the file; a Collada file's point, spot
 * and directional lights through Assimp (full cone angles halved, an ambient light
 * skipped, the units warning once); ASCII FBX files' point, spot and directional lights
 * through Assimp (node transforms with a parent's rotation and scale, a pre-rotation and
 * the Euler order, Intensity as a percentage, full cone angles in degrees, the file in
 * centimetres, nodes sharing a name, the decay and area-light warnings, a negative
 * intensity refused) and the illuminance they give on the floor in lux with the file's
 * unit; `radiosity info` listing each light, and its --stats counting them; the
 * false-colour legend's unit following the lights (lx, cd/m^2, or "relative").
 *
 * Every expected position, direction and illuminance is worked out by hand in the
 * comments.
 */
#include <png.h>
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
        CHECK(!bulb->unit_unknown); /* glTF: candela */
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
        CHECK(lamp->unit_unknown);
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
                      "(0, -0.866025, -0.5)  intensity (5, 6, 7) in no known unit (taken as "
                      "cd)  cone 20 to 30 degrees from the axis\n") != NULL);
    CHECK(strstr(out, "  sun         sunnode                   direction (0, -1, 0)  "
                      "intensity (1000, 900, 800) in no known unit (taken as lux)\n") != NULL);
}

/* An ASCII FBX 7.4 file: Y up, UnitScaleFactor `unit` (centimetres per file unit), the
 * given Objects and Connections bodies. */
static const char *write_fbx(const char *name, double unit, const char *objects,
                             const char *connections)
{
    static char text[16384];
    snprintf(text, sizeof(text),
             "; FBX 7.4.0 project file\n"
             "FBXHeaderExtension:  {\n\tFBXHeaderVersion: 1003\n\tFBXVersion: 7400\n}\n"
             "GlobalSettings:  {\n\tVersion: 1000\n\tProperties70:  {\n"
             "\t\tP: \"UpAxis\", \"int\", \"Integer\", \"\",1\n"
             "\t\tP: \"UpAxisSign\", \"int\", \"Integer\", \"\",1\n"
             "\t\tP: \"UnitScaleFactor\", \"double\", \"Number\", \"\",%g\n"
             "\t}\n}\n"
             "Objects:  {\n%s}\n"
             "Connections:  {\n%s}\n",
             unit, objects, connections);
    return test_write_file(name, text);
}

/* A 10 m x 10 m floor in centimetres (y = 0, facing +y: the corners 0, 3, 2, 1 turn
 * counter-clockwise seen from above), geometry 100 under model 101 "floor". */
#define FBX_FLOOR                                                                          \
    "\tGeometry: 100, \"Geometry::floor\", \"Mesh\" {\n"                                   \
    "\t\tVertices: *12 {\n\t\t\ta: -500,0,-500,500,0,-500,500,0,500,-500,0,500\n\t\t}\n"   \
    "\t\tPolygonVertexIndex: *4 {\n\t\t\ta: 0,3,2,-2\n\t\t}\n\t}\n"                         \
    "\tModel: 101, \"Model::floor\", \"Mesh\" {\n\t\tVersion: 232\n\t}\n"
#define FBX_FLOOR_LINKS "\tC: \"OO\",101,0\n\tC: \"OO\",100,101\n"

/* The FBX scene, in centimetres (UnitScaleFactor 1: unit_metres 0.01). FBX lights shine
 * along their node's -Y; Lcl Rotation (a, b, c) is R = Rz(c) Ry(b) Rx(a) (Euler XYZ, x
 * first); a node's transform is T Rpre R S. With Rx(90) (x,y,z) = (x, -z, y),
 * Ry(b) (x,y,z) = (x cos b + z sin b, y, -x sin b + z cos b), Rz(90) (x,y,z) = (-y, x, z):
 * - "rig" (a Null): T (100,0,0), R = Rz(90), S = 2: p -> (100,0,0) + 2 Rz(90) p.
 * - "bulbnode" under rig: T (100,20,20); a point light, Color (1,0.5,0.25), Intensity 400
 *   (percent): intensity (4, 2, 1); position (100,0,0) + 2 (-20,100,20) = (60, 200, 40).
 * - "spotnode" under rig: T (75,0,0), Lcl Rotation (90,60,0); a spot, Intensity 1000:
 *   intensity 10; InnerAngle 40, OuterAngle 60 (full angles, degrees): half-angles 20 and
 *   30; position (100,0,0) + 2 (0,75,0) = (100,150,0); direction Rx(90) (0,-1,0) =
 *   (0,0,-1), Ry(60) -> (-sin 60, 0, -cos 60), Rz(90) -> (0, -0.8660254, -0.5).
 * - "sunnode": PreRotation (0,90,0) (RotationActive), Lcl Rotation (-30,0,0); a
 *   directional light, Color (1,0.9,0.8), Intensity 1000: (10, 9, 8) lux; direction
 *   Rx(-30) (0,-1,0) = (0, -cos 30, sin 30), Ry(90) -> (sin 30, -cos 30, 0) =
 *   (0.5, -0.8660254, 0).
 * - "panelnode": an area light (LightType 3), not read, with a warning. */
static const char fbx_objects[] =
    FBX_FLOOR
    "\tModel: 200, \"Model::rig\", \"Null\" {\n\t\tVersion: 232\n\t\tProperties70:  {\n"
    "\t\t\tP: \"Lcl Translation\", \"Lcl Translation\", \"\", \"A\",100,0,0\n"
    "\t\t\tP: \"Lcl Rotation\", \"Lcl Rotation\", \"\", \"A\",0,0,90\n"
    "\t\t\tP: \"Lcl Scaling\", \"Lcl Scaling\", \"\", \"A\",2,2,2\n\t\t}\n\t}\n"
    "\tNodeAttribute: 211, \"NodeAttribute::bulb\", \"Light\" {\n\t\tProperties70:  {\n"
    "\t\t\tP: \"LightType\", \"enum\", \"\", \"\",0\n"
    "\t\t\tP: \"Color\", \"Color\", \"\", \"A\",1,0.5,0.25\n"
    "\t\t\tP: \"Intensity\", \"Number\", \"\", \"A\",400\n\t\t}\n"
    "\t\tTypeFlags: \"Light\"\n\t}\n"
    "\tModel: 210, \"Model::bulbnode\", \"Light\" {\n\t\tVersion: 232\n\t\tProperties70:  {\n"
    "\t\t\tP: \"Lcl Translation\", \"Lcl Translation\", \"\", \"A\",100,20,20\n\t\t}\n\t}\n"
    "\tNodeAttribute: 221, \"NodeAttribute::spot\", \"Light\" {\n\t\tProperties70:  {\n"
    "\t\t\tP: \"LightType\", \"enum\", \"\", \"\",2\n"
    "\t\t\tP: \"Color\", \"Color\", \"\", \"A\",1,1,1\n"
    "\t\t\tP: \"Intensity\", \"Number\", \"\", \"A\",1000\n"
    "\t\t\tP: \"InnerAngle\", \"Number\", \"\", \"A\",40\n"
    "\t\t\tP: \"OuterAngle\", \"Number\", \"\", \"A\",60\n\t\t}\n"
    "\t\tTypeFlags: \"Light\"\n\t}\n"
    "\tModel: 220, \"Model::spotnode\", \"Light\" {\n\t\tVersion: 232\n\t\tProperties70:  {\n"
    "\t\t\tP: \"Lcl Translation\", \"Lcl Translation\", \"\", \"A\",75,0,0\n"
    "\t\t\tP: \"Lcl Rotation\", \"Lcl Rotation\", \"\", \"A\",90,60,0\n\t\t}\n\t}\n"
    "\tNodeAttribute: 231, \"NodeAttribute::sun\", \"Light\" {\n\t\tProperties70:  {\n"
    "\t\t\tP: \"LightType\", \"enum\", \"\", \"\",1\n"
    "\t\t\tP: \"Color\", \"Color\", \"\", \"A\",1,0.9,0.8\n"
    "\t\t\tP: \"Intensity\", \"Number\", \"\", \"A\",1000\n\t\t}\n"
    "\t\tTypeFlags: \"Light\"\n\t}\n"
    "\tModel: 230, \"Model::sunnode\", \"Light\" {\n\t\tVersion: 232\n\t\tProperties70:  {\n"
    "\t\t\tP: \"RotationActive\", \"bool\", \"\", \"\",1\n"
    "\t\t\tP: \"PreRotation\", \"Vector3D\", \"Vector\", \"\",0,90,0\n"
    "\t\t\tP: \"Lcl Rotation\", \"Lcl Rotation\", \"\", \"A\",-30,0,0\n\t\t}\n\t}\n"
    "\tNodeAttribute: 241, \"NodeAttribute::panel\", \"Light\" {\n\t\tProperties70:  {\n"
    "\t\t\tP: \"LightType\", \"enum\", \"\", \"\",3\n\t\t}\n"
    "\t\tTypeFlags: \"Light\"\n\t}\n"
    "\tModel: 240, \"Model::panelnode\", \"Light\" {\n\t\tVersion: 232\n\t}\n";
static const char fbx_links[] = FBX_FLOOR_LINKS
    "\tC: \"OO\",200,0\n\tC: \"OO\",210,200\n\tC: \"OO\",211,210\n"
    "\tC: \"OO\",220,200\n\tC: \"OO\",221,220\n"
    "\tC: \"OO\",230,0\n\tC: \"OO\",231,230\n"
    "\tC: \"OO\",240,0\n\tC: \"OO\",241,240\n";

#define SIN60 0.86602540378443865

static void fbx_lights(void)
{
    const char *path = write_fbx("lights.fbx", 1, fbx_objects, fbx_links);
    warning_log log = {{0}, 0};
    rad_error error;
    rad_scene *scene = load(path, &log, &error);
    if (!scene) {
        test_fail(__FILE__, __LINE__, "lights.fbx: %s", error.message);
        return;
    }
    CHECK_NEAR(scene->unit_metres, 0.01, 1e-12);
    CHECK(scene->light_count == 3);
    const rad_light *bulb = light_named(scene, "bulbnode");
    if (bulb) {
        CHECK(bulb->type == RAD_LIGHT_POINT);
        check_vec(bulb->position, 60, 200, 40, 1e-4);
        CHECK_NEAR(bulb->intensity.r, 4, 1e-6);
        CHECK_NEAR(bulb->intensity.g, 2, 1e-6);
        CHECK_NEAR(bulb->intensity.b, 1, 1e-6);
        CHECK(bulb->unit_unknown);
    }
    const rad_light *spot = light_named(scene, "spotnode");
    if (spot) {
        CHECK(spot->type == RAD_LIGHT_SPOT);
        check_vec(spot->position, 100, 150, 0, 1e-4);
        check_vec(spot->direction, 0, -SIN60, -0.5, 1e-6);
        CHECK_NEAR(spot->inner_degrees, 20, 1e-5);
        CHECK_NEAR(spot->outer_degrees, 30, 1e-5);
        CHECK_NEAR(spot->intensity.g, 10, 1e-6);
    }
    const rad_light *sun = light_named(scene, "sunnode");
    if (sun) {
        CHECK(sun->type == RAD_LIGHT_DIRECTIONAL);
        check_vec(sun->direction, 0.5, -SIN60, 0, 1e-6);
        CHECK_NEAR(sun->intensity.r, 10, 1e-6);
        CHECK_NEAR(sun->intensity.g, 9, 1e-6);
        CHECK_NEAR(sun->intensity.b, 8, 1e-6);
    }
    CHECK(occurrences(log.text, "'panelnode' is an area or volume light") == 1);
    CHECK(occurrences(log.text, "3 lights in no known unit") == 1);
    CHECK(occurrences(log.text, "decay") == 0); /* Assimp's default decay: quadratic */
    rad_scene_destroy(scene);
}

/* The illuminance (E_r, lux) the FBX lights give at floor points, normal up, through
 * `radiosity illuminance`: distances in metres (the file's centimetres x 0.01), nothing
 * reflected (a floor alone sees no surface). Point-like lights: E = I cos / d^2, cos =
 * height / d; the sun: E_n cos 30 degrees = 10 x 0.8660254 = 8.660254.
 * - (60, 0, 40), below the bulb: bulb 4 / 2^2 = 1; the spot's axis is 46.7 degrees away
 *   (outside its 30): 0; total 9.660254.
 * - (100, 0, -86.60254), where the spot's axis meets the floor (t = 150 / cos 30 =
 *   173.205 cm along it): spot 10 cos 30 / 1.7320508^2 = 2.8867513; bulb at d^2 =
 *   (0.4^2 + 2^2 + 1.2660254^2) m^2 = 5.7628203, 4 x (2 / 2.4005875) / 5.7628203 =
 *   0.5782755; total 12.1252808.
 * Were the unit ignored (metres), the bulb would give 1e-4 below it. */
static void fbx_illuminance(void)
{
    test_write_file("fbx_points.csv", "60,0,40\n100,0,-86.6025404\n");
    CHECK(test_run_tool("illuminance lights.fbx --points fbx_points.csv --gather-rays 16 "
                        "-o fbx_lux.csv --quiet") == 0);
    const char *csv = test_read_text(test_path("fbx_lux.csv"));
    const double expected[2] = {1 + 10 * SIN60,
                                10 * SIN60 / 3 + 4 * (2 / sqrt(5.7628203)) / 5.7628203 +
                                    10 * SIN60};
    CHECK_NEAR(expected[1], 12.1252808, 1e-6);
    const char *line = csv ? strchr(csv, '\n') : NULL;
    for (int k = 0; k < 2; k++, line = line ? strchr(line + 1, '\n') : NULL) {
        double v[10];
        if (!line || sscanf(line + 1, "%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf", &v[0], &v[1],
                            &v[2], &v[3], &v[4], &v[5], &v[6], &v[7], &v[8], &v[9]) != 10) {
            test_fail(__FILE__, __LINE__, "fbx_lux.csv: no row %d in:\n%s", k + 1,
                      csv ? csv : "(none)");
            return;
        }
        CHECK_NEAR(v[6], expected[k], 1e-5);
    }
}

/* Nodes sharing a name, in inches (UnitScaleFactor 2.54: unit_metres 0.0254): one point
 * light (DecayType 0: no decay) instanced under two nodes named "lamp", after a mesh node
 * of that name too. In the node walk: "lamp" (the mesh), "shelf" (T (0,100,0)) > "lamp"
 * (the first light, at (0,100,0)), "lamp" (T (300,250,0): the second, at (300,250,0)).
 * Each light warns of its decay once. */
static void fbx_shared_names(void)
{
    static const char objects[] =
        "\tGeometry: 100, \"Geometry::floor\", \"Mesh\" {\n"
        "\t\tVertices: *12 {\n\t\t\ta: -500,0,-500,500,0,-500,500,0,500,-500,0,500\n\t\t}\n"
        "\t\tPolygonVertexIndex: *4 {\n\t\t\ta: 0,3,2,-2\n\t\t}\n\t}\n"
        "\tModel: 101, \"Model::lamp\", \"Mesh\" {\n\t\tVersion: 232\n\t}\n"
        "\tModel: 300, \"Model::shelf\", \"Null\" {\n\t\tVersion: 232\n\t\tProperties70:  {\n"
        "\t\t\tP: \"Lcl Translation\", \"Lcl Translation\", \"\", \"A\",0,100,0\n\t\t}\n\t}\n"
        "\tNodeAttribute: 311, \"NodeAttribute::bulb\", \"Light\" {\n\t\tProperties70:  {\n"
        "\t\t\tP: \"LightType\", \"enum\", \"\", \"\",0\n"
        "\t\t\tP: \"DecayType\", \"enum\", \"\", \"\",0\n\t\t}\n"
        "\t\tTypeFlags: \"Light\"\n\t}\n"
        "\tModel: 310, \"Model::lamp\", \"Light\" {\n\t\tVersion: 232\n\t}\n"
        "\tModel: 320, \"Model::lamp\", \"Light\" {\n\t\tVersion: 232\n\t\tProperties70:  {\n"
        "\t\t\tP: \"Lcl Translation\", \"Lcl Translation\", \"\", \"A\",300,250,0\n\t\t}\n\t}\n";
    static const char links[] = FBX_FLOOR_LINKS "\tC: \"OO\",300,0\n\tC: \"OO\",310,300\n"
                                "\tC: \"OO\",311,310\n\tC: \"OO\",320,0\n\tC: \"OO\",311,320\n";
    const char *path = write_fbx("twins.fbx", 2.54, objects, links);
    warning_log log = {{0}, 0};
    rad_error error;
    rad_scene *scene = load(path, &log, &error);
    if (!scene) {
        test_fail(__FILE__, __LINE__, "twins.fbx: %s", error.message);
        return;
    }
    CHECK_NEAR(scene->unit_metres, 0.0254, 1e-9);
    CHECK(scene->light_count == 2);
    if (scene->light_count == 2) {
        check_vec(scene->lights[0].position, 0, 100, 0, 1e-4);
        check_vec(scene->lights[1].position, 300, 250, 0, 1e-4);
        CHECK_NEAR(scene->lights[1].intensity.g, 1, 1e-6); /* FBX defaults: white, 100 % */
    }
    CHECK(occurrences(log.text, "'lamp': its FBX decay is none") == 2);
    CHECK(occurrences(log.text, "several nodes") == 0);
    rad_scene_destroy(scene);
}

/* A negative FBX intensity: refused, the file and the light named, on one line. */
static void fbx_refusal(void)
{
    static const char objects[] =
        FBX_FLOOR
        "\tNodeAttribute: 411, \"NodeAttribute::bad\", \"Light\" {\n\t\tProperties70:  {\n"
        "\t\t\tP: \"LightType\", \"enum\", \"\", \"\",0\n"
        "\t\t\tP: \"Intensity\", \"Number\", \"\", \"A\",-100\n\t\t}\n"
        "\t\tTypeFlags: \"Light\"\n\t}\n"
        "\tModel: 410, \"Model::badnode\", \"Light\" {\n\t\tVersion: 232\n\t}\n";
    const char *path = write_fbx("negative.fbx", 1, objects,
                                 FBX_FLOOR_LINKS "\tC: \"OO\",410,0\n\tC: \"OO\",411,410\n");
    warning_log log = {{0}, 0};
    rad_error error;
    rad_scene *scene = load(path, &log, &error);
    CHECK(!scene && error.status == RAD_ERR_PARSE);
    CHECK(strstr(error.message, "negative.fbx") && strstr(error.message, "'badnode'"));
    CHECK(strchr(error.message, '\n') == NULL);
    rad_scene_destroy(scene);
    CHECK(test_run_tool("render negative.fbx --size 8x8 -o negative.png") == 1);
    CHECK(!test_file_exists(test_path("negative.png")));
}

/* `radiosity info` on the FBX file: each light, its intensity in no known unit, and the
 * light count in --stats. */
static void info_lists_fbx_lights(void)
{
    int code = test_run_tool("info lights.fbx --stats info.json");
    const char *out = test_read_text(test_path("stdout.txt"));
    CHECK(code == 0);
    CHECK(strstr(out, "unit: 0.01 m\n") != NULL);
    CHECK(strstr(out, "lights: 3\n") != NULL);
    static const char *lines[] = {
        "  point       bulbnode                  position (60, 200, 40)  intensity (4, 2, 1) "
        "in no known unit (taken as cd)\n",
        "  spot        spotnode                  position (100, 150, 0)  direction (0, "
        "-0.866025, -0.5)  intensity (10, 10, 10) in no known unit (taken as cd)  cone 20 to "
        "30 degrees from the axis\n",
        "  sun         sunnode                   direction (0.5, -0.866025, 0)  intensity (10, "
        "9, 8) in no known unit (taken as lux)\n",
    };
    for (size_t k = 0; k < sizeof(lines) / sizeof(lines[0]); k++)
        if (!strstr(out, lines[k]))
            test_fail(__FILE__, __LINE__, "info lights.fbx lacks the line:\n%sin:\n%s", lines[k],
                      out);
    const char *stats = test_read_text(test_path("info.json"));
    CHECK(stats && strstr(stats, "\"lights\": 3,") != NULL);
    code = test_run_tool("info lights.gltf --stats info.json");
    CHECK(code == 0);
    stats = test_read_text(test_path("info.json"));
    CHECK(stats && strstr(stats, "\"lights\": 4,") != NULL);
}

/* The white pixels of the legend's unit (the rows above its bar, x from the image's
 * width on) in `png` agree with rad_image_false_colour's drawing of `unit` beside an
 * image of that size. */
static bool legend_says(const char *png_name, uint32_t width, uint32_t height, const char *unit)
{
    rad_image *values = test_new_image(width, height), *drawn = NULL;
    rad_false_colour_options options = {.low = 0, .high = 1, .unit = unit};
    rad_error error;
    bool same = rad_image_false_colour(values, &options, &drawn, &error) == RAD_OK;
    png_image png = {.version = PNG_IMAGE_VERSION};
    uint32_t full = width + 96;
    unsigned char *decoded = malloc((size_t)full * height * 3);
    same = same && decoded && png_image_begin_read_from_file(&png, test_path(png_name));
    if (same) {
        png.format = PNG_FORMAT_RGB;
        same = png.width == full && png.height == height && drawn->width == full &&
               png_image_finish_read(&png, NULL, decoded, 0, NULL);
    }
    int lit = 0;
    for (uint32_t y = 0; same && y < 12; y++) /* the unit: rows 2 to 11; the bar from 16 */
        for (uint32_t x = width; x < full; x++) {
            bool white = decoded[((size_t)y * full + x) * 3] > 128;
            same = same && white == (test_pixel(drawn, x, y)[0] > 0.5f);
            lit += white;
        }
    png_image_free(&png);
    free(decoded);
    rad_image_destroy(drawn);
    rad_image_destroy(values);
    return same && lit > 0;
}

/* render --false-colour: the legend says lx (illuminance) or cd/m^2 (radiance) with the
 * glTF file's photometric lights, "relative" with the FBX file's lights in no known unit
 * and with emitters alone (an OBJ's Ke). The check tells the units apart. */
static void legend_follows_lights(void)
{
    static const char view[] = "--size 40x30 --eye 0,8,0 --target 0,0,0 --up 0,0,-1 --quiet";
    char command[512];
    snprintf(command, sizeof(command),
             "render lights.gltf --quantity illuminance --false-colour %s -o gltf_lux.png", view);
    CHECK(test_run_tool(command) == 0);
    CHECK(legend_says("gltf_lux.png", 40, 30, "lx"));
    CHECK(!legend_says("gltf_lux.png", 40, 30, "relative"));
    snprintf(command, sizeof(command), "render lights.gltf --false-colour %s -o gltf_cd.png",
             view);
    CHECK(test_run_tool(command) == 0);
    CHECK(legend_says("gltf_cd.png", 40, 30, "cd/m^2"));
    CHECK(test_run_tool("render lights.fbx --quantity illuminance --false-colour --size 40x30 "
                        "--eye 0,800,0 --target 0,0,0 --up 0,0,-1 --quiet -o fbx_lux.png") == 0);
    CHECK(legend_says("fbx_lux.png", 40, 30, "relative"));
    CHECK(!legend_says("fbx_lux.png", 40, 30, "lx"));
    test_write_file("glow.obj", "mtllib glow.mtl\nv -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\n"
                                "v -1 2 -1\nv 1 2 -1\nv 1 2 1\nv -1 2 1\n"
                                "usemtl floor\nf 1 4 3 2\nusemtl glow\nf 5 6 7 8\n");
    test_write_file("glow.mtl", "newmtl floor\nKd 0.5 0.5 0.5\nnewmtl glow\nKd 0 0 0\n"
                                "Ke 1 1 1\n");
    CHECK(test_run_tool("render glow.obj --quantity illuminance --false-colour --size 40x30 "
                        "--eye 0,1,0 --target 0,0,0 --up 0,0,-1 --quiet -o glow_lux.png") == 0);
    CHECK(legend_says("glow_lux.png", 40, 30, "relative"));
}

int main(void)
{
    test_tmpdir();
    gltf_lights();
    gltf_refusals();
    collada_lights();
    info_lists_lights();
    fbx_lights();
    fbx_illuminance();
    fbx_shared_names();
    fbx_refusal();
    info_lists_fbx_lights();
    legend_follows_lights();
    return test_finish("test_file_lights");
}
