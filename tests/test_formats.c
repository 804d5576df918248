/*
 * test_formats.c - one scene written by this test in OBJ + MTL, glTF (JSON + external
 * buffer), glb, STL and PLY gives the same radiosity solution within 1e-4 relative
 * (area-weighted mean exitance of each face of a closed box, direct solve). STL and PLY
 * carry no materials: they start at the default grey and get theirs through
 * rad_scene_set_material (what --emit / --albedo call). Also: glTF emitted radiance is
 * emissiveFactor x KHR_materials_emissive_strength, with Assimp's material numbering
 * (by first use, unused ones dropped) tied back to the file's; a glTF camera is placed by
 * its node and its vertical field of view recovered; the two Cornell box files load and
 * render, the wild one lit through --emit. Collada, 3DS and FBX have no writer here: the
 * OBJ goes through Assimp's exporters (a round trip, so only a check that those readers
 * reach the same scene); FBX's up axis and unit are set in its text and read back.
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <assimp/cexport.h>
#include <assimp/cimport.h>
#include <assimp/scene.h>

#include "testlib.h"

/* The box [0,1]^3, every face's front inward; corners counter-clockwise from inside. */
typedef struct face {
    const char *name, *material;
    double corner[4][3];
} face;

static const face box[6] = {
    {"floor", "white", {{0, 0, 0}, {0, 0, 1}, {1, 0, 1}, {1, 0, 0}}},
    {"ceiling", "lamp", {{0, 1, 0}, {1, 1, 0}, {1, 1, 1}, {0, 1, 1}}},
    {"left", "red", {{0, 0, 0}, {0, 1, 0}, {0, 1, 1}, {0, 0, 1}}},
    {"right", "green", {{1, 0, 0}, {1, 0, 1}, {1, 1, 1}, {1, 1, 0}}},
    {"back", "white", {{0, 0, 1}, {0, 1, 1}, {1, 1, 1}, {1, 0, 1}}},
    {"front", "white", {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}},
};

typedef struct material_values {
    const char *name;
    double albedo[3], emission[3];
} material_values;

static const material_values materials[4] = {
    {"white", {0.7, 0.7, 0.7}, {0, 0, 0}},
    {"lamp", {0.2, 0.2, 0.2}, {4, 4, 4}},
    {"red", {0.6, 0.1, 0.1}, {0, 0, 0}},
    {"green", {0.1, 0.6, 0.1}, {0, 0, 0}},
};

static const material_values *material_named(const char *name)
{
    for (int m = 0; m < 4; m++)
        if (strcmp(materials[m].name, name) == 0)
            return &materials[m];
    return NULL;
}

static FILE *open_scratch(const char *name)
{
    FILE *file = fopen(test_path(name), "wb");
    if (!file) {
        test_fail(__FILE__, __LINE__, "cannot write %s", name);
        exit(1);
    }
    return file;
}

static void write_obj(void)
{
    FILE *mtl = open_scratch("box.mtl");
    for (int m = 0; m < 4; m++)
        fprintf(mtl, "newmtl %s\nKd %g %g %g\nKe %g %g %g\n", materials[m].name,
                materials[m].albedo[0], materials[m].albedo[1], materials[m].albedo[2],
                materials[m].emission[0], materials[m].emission[1], materials[m].emission[2]);
    fclose(mtl);
    FILE *obj = open_scratch("box.obj");
    fprintf(obj, "mtllib box.mtl\n");
    for (int f = 0; f < 6; f++) {
        fprintf(obj, "o %s\nusemtl %s\n", box[f].name, box[f].material);
        for (int k = 0; k < 4; k++)
            fprintf(obj, "v %g %g %g\n", box[f].corner[k][0], box[f].corner[k][1],
                    box[f].corner[k][2]);
        int base = 4 * f + 1;
        fprintf(obj, "f %d %d %d\nf %d %d %d\n", base, base + 1, base + 2, base, base + 2,
                base + 3);
    }
    fclose(obj);
}

static void write_stl(void)
{
    FILE *stl = open_scratch("box.stl");
    static const int tri[2][3] = {{0, 1, 2}, {0, 2, 3}};
    for (int f = 0; f < 6; f++) {
        fprintf(stl, "solid %s\n", box[f].name);
        for (int t = 0; t < 2; t++) {
            fprintf(stl, "facet normal 0 0 0\nouter loop\n");
            for (int k = 0; k < 3; k++) {
                const double *c = box[f].corner[tri[t][k]];
                fprintf(stl, "vertex %g %g %g\n", c[0], c[1], c[2]);
            }
            fprintf(stl, "endloop\nendfacet\n");
        }
        fprintf(stl, "endsolid %s\n", box[f].name);
    }
    fclose(stl);
}

/* The box as glTF: positions (float) then indices (uint16) of each face; one mesh and one
 * node per face. Materials are listed in an order their first use does not follow, with
 * an unused first entry, and the lamp's radiance is emissiveFactor 0.5 x strength 8. */
static size_t gltf_buffer(unsigned char *buffer)
{
    size_t at = 0;
    for (int f = 0; f < 6; f++)
        for (int k = 0; k < 4; k++)
            for (int a = 0; a < 3; a++) {
                float v = (float)box[f].corner[k][a];
                memcpy(buffer + at, &v, 4);
                at += 4;
            }
    static const uint16_t indices[6] = {0, 1, 2, 0, 2, 3};
    memcpy(buffer + at, indices, sizeof(indices));
    at += sizeof(indices);
    return at;
}

static char *gltf_json(const char *buffer_uri, size_t buffer_length)
{
    static char json[16384];
    size_t n = 0;
#define ADD(...) n += (size_t)snprintf(json + n, sizeof(json) - n, __VA_ARGS__)
    ADD("{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0,1,2,3,4,5]}],");
    ADD("\"nodes\":[");
    for (int f = 0; f < 6; f++)
        ADD("%s{\"mesh\":%d,\"name\":\"node_%s\"}", f ? "," : "", f, box[f].name);
    /* file order: unused, green, red, lamp, white */
    static const char *order[5] = {"unused", "green", "red", "lamp", "white"};
    ADD("],\"meshes\":[");
    for (int f = 0; f < 6; f++) {
        int material = 0;
        for (int m = 1; m < 5; m++)
            if (strcmp(order[m], box[f].material) == 0)
                material = m;
        ADD("%s{\"name\":\"%s\",\"primitives\":[{\"attributes\":{\"POSITION\":%d},"
            "\"indices\":6,\"material\":%d}]}",
            f ? "," : "", box[f].name, f, material);
    }
    ADD("],\"materials\":[{\"name\":\"unused\",\"emissiveFactor\":[1,1,1],\"extensions\":"
        "{\"KHR_materials_emissive_strength\":{\"emissiveStrength\":100}}}");
    for (int m = 1; m < 5; m++) {
        const material_values *v = material_named(order[m]);
        ADD(",{\"name\":\"%s\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[%g,%g,%g,1],"
            "\"metallicFactor\":0}",
            v->name, v->albedo[0], v->albedo[1], v->albedo[2]);
        if (v->emission[0] > 0)
            ADD(",\"emissiveFactor\":[%g,%g,%g],\"extensions\":{"
                "\"KHR_materials_emissive_strength\":{\"emissiveStrength\":8}}",
                v->emission[0] / 8, v->emission[1] / 8, v->emission[2] / 8);
        ADD("}");
    }
    ADD("],\"extensionsUsed\":[\"KHR_materials_emissive_strength\"],");
    ADD("\"buffers\":[{\"byteLength\":%zu%s%s%s}],", buffer_length, buffer_uri ? ",\"uri\":\"" : "",
        buffer_uri ? buffer_uri : "", buffer_uri ? "\"" : "");
    ADD("\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":288},"
        "{\"buffer\":0,\"byteOffset\":288,\"byteLength\":12}],\"accessors\":[");
    for (int f = 0; f < 6; f++) {
        double lo[3] = {1, 1, 1}, hi[3] = {0, 0, 0};
        for (int k = 0; k < 4; k++)
            for (int a = 0; a < 3; a++) {
                lo[a] = fmin(lo[a], box[f].corner[k][a]);
                hi[a] = fmax(hi[a], box[f].corner[k][a]);
            }
        ADD("{\"bufferView\":0,\"byteOffset\":%d,\"componentType\":5126,\"count\":4,"
            "\"type\":\"VEC3\",\"min\":[%g,%g,%g],\"max\":[%g,%g,%g]},",
            48 * f, lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]);
    }
    ADD("{\"bufferView\":1,\"componentType\":5123,\"count\":6,\"type\":\"SCALAR\"}]}");
#undef ADD
    return json;
}

static void put_u32(FILE *file, uint32_t v)
{
    unsigned char b[4] = {(unsigned char)v, (unsigned char)(v >> 8), (unsigned char)(v >> 16),
                          (unsigned char)(v >> 24)};
    fwrite(b, 1, 4, file);
}

/* A .glb of `json` and `bin` (both padded to 4 bytes); `cut` > 0 keeps only that many
 * bytes (a truncated file). */
static void write_glb(const char *name, const char *json, const unsigned char *bin,
                      size_t bin_length, size_t cut)
{
    size_t json_length = strlen(json), json_padded = (json_length + 3) & ~(size_t)3;
    size_t bin_padded = (bin_length + 3) & ~(size_t)3;
    size_t total = 12 + 8 + json_padded + 8 + bin_padded;
    FILE *file = open_scratch(name);
    put_u32(file, 0x46546C67u);
    put_u32(file, 2);
    put_u32(file, (uint32_t)total);
    put_u32(file, (uint32_t)json_padded);
    put_u32(file, 0x4E4F534Au);
    fwrite(json, 1, json_length, file);
    for (size_t k = json_length; k < json_padded; k++)
        fputc(' ', file);
    put_u32(file, (uint32_t)bin_padded);
    put_u32(file, 0x004E4942u);
    fwrite(bin, 1, bin_length, file);
    for (size_t k = bin_length; k < bin_padded; k++)
        fputc(0, file);
    fclose(file);
    if (cut > 0 && truncate(test_path(name), (off_t)cut) != 0)
        test_fail(__FILE__, __LINE__, "truncate failed");
}

static void write_gltf_files(void)
{
    unsigned char bin[512];
    size_t length = gltf_buffer(bin);
    FILE *file = open_scratch("box.bin");
    fwrite(bin, 1, length, file);
    fclose(file);
    test_write_file("box.gltf", gltf_json("box.bin", length));
    write_glb("box.glb", gltf_json(NULL, length), bin, length, 0);
    /* bad variants for the error checks */
    write_glb("cut.glb", gltf_json(NULL, length), bin, length, 200);
    test_write_file("nobuffer.gltf", gltf_json("missing.bin", length));
}

/* Area-weighted mean exitance of the patches facing each axis direction (the 6 faces). */
static bool solve_faces(const char *name, const rad_scene *scene, rad_rgb mean[6])
{
    rad_error error;
    rad_mesh *mesh = NULL;
    rad_rgb *B = NULL;
    bool ok = rad_mesh_build(scene, 0.25, &mesh, &error) == RAD_OK;
    if (ok) {
        B = calloc(mesh->patch_count, sizeof(*B));
        rad_scene_solve_options solve = {.solver = RAD_SOLVER_DIRECT, .seed = 7};
        ok = B && rad_solve_scene(scene, mesh, &solve, B, NULL, &error) == RAD_OK;
    }
    if (!ok)
        test_fail(__FILE__, __LINE__, "%s: %s", name, error.message);
    double area[6] = {0};
    memset(mean, 0, 6 * sizeof(*mean));
    for (uint32_t p = 0; ok && p < mesh->patch_count; p++) {
        const rad_patch *patch = &mesh->patches[p];
        const double *n = &patch->normal.x;
        int axis = 0;
        for (int a = 1; a < 3; a++)
            if (fabs(n[a]) > fabs(n[axis]))
                axis = a;
        int bin = 2 * axis + (n[axis] < 0);
        area[bin] += patch->area;
        mean[bin].r += patch->area * B[p].r;
        mean[bin].g += patch->area * B[p].g;
        mean[bin].b += patch->area * B[p].b;
    }
    for (int k = 0; k < 6; k++)
        if (area[k] > 0)
            mean[k] = (rad_rgb){mean[k].r / area[k], mean[k].g / area[k], mean[k].b / area[k]};
    free(B);
    rad_mesh_destroy(mesh);
    return ok;
}

static const rad_material *surface_material(const rad_scene *scene, const char *surface)
{
    for (uint32_t s = 0; s < scene->surface_count; s++)
        if (strcmp(scene->surfaces[s].name, surface) == 0)
            return &scene->materials[scene->triangles[scene->surfaces[s].first_triangle].material];
    test_fail(__FILE__, __LINE__, "no surface '%s' in %s", surface, scene->source);
    return NULL;
}

static void check_box_materials(const rad_scene *scene)
{
    CHECK(scene->surface_count == 6);
    for (int f = 0; f < 6; f++) {
        const rad_material *m = surface_material(scene, box[f].name);
        const material_values *v = material_named(box[f].material);
        if (!m)
            continue;
        CHECK_NEAR(m->albedo.r, v->albedo[0], 1e-6);
        CHECK_NEAR(m->albedo.g, v->albedo[1], 1e-6);
        CHECK_NEAR(m->emission.r, v->emission[0], 1e-6);
        CHECK_NEAR(m->emission.b, v->emission[2], 1e-6);
    }
}

static void compare_faces(const char *name, const rad_rgb got[6], const rad_rgb want[6])
{
    for (int k = 0; k < 6; k++) {
        if (fabs(got[k].r - want[k].r) > 1e-4 * want[k].r)
            fprintf(stderr, "%s: face %d: %.9g vs %.9g\n", name, k, got[k].r, want[k].r);
        CHECK_NEAR(got[k].r, want[k].r, 1e-4);
        CHECK_NEAR(got[k].g, want[k].g, 1e-4);
        CHECK_NEAR(got[k].b, want[k].b, 1e-4);
    }
}

static int by_red(const void *a, const void *b)
{
    const rad_rgb *x = a, *y = b;
    return (x->r > y->r) - (x->r < y->r);
}

/* The same six faces in any order: for a file whose axes were turned. */
static void compare_faces_turned(const char *name, const rad_rgb got[6], const rad_rgb want[6])
{
    rad_rgb a[6], b[6];
    memcpy(a, got, sizeof(a));
    memcpy(b, want, sizeof(b));
    qsort(a, 6, sizeof(*a), by_red);
    qsort(b, 6, sizeof(*b), by_red);
    compare_faces(name, a, b);
}

static void same_solution_in_every_format(void)
{
    write_obj();
    write_stl();
    write_gltf_files();
    rad_rgb reference[6], got[6];
    rad_scene *obj = test_load_scene("box.obj");
    if (!obj || !solve_faces("box.obj", obj, reference))
        return;
    check_box_materials(obj);
    /* the solution is not trivial: the lamp (ceiling, -y bin 3) shines above its own
     * exitance, the red wall (+x bin 0) is red, the green one (-x bin 1) green */
    CHECK(reference[3].r > 3.14159 * 4);
    CHECK(reference[0].r > 2 * reference[0].g);
    CHECK(reference[1].g > 2 * reference[1].r);
    rad_scene_destroy(obj);

    const char *gltf_names[2] = {"box.gltf", "box.glb"};
    for (int k = 0; k < 2; k++) {
        rad_scene *scene = test_load_scene(gltf_names[k]);
        if (!scene)
            continue;
        check_box_materials(scene);
        CHECK(scene->unit_metres == 1);
        if (solve_faces(gltf_names[k], scene, got))
            compare_faces(gltf_names[k], got, reference);
        rad_scene_destroy(scene);
    }

    /* STL: no materials: everything starts at the default grey; materials set by name */
    rad_scene *stl = test_load_scene("box.stl");
    if (stl) {
        const rad_material *m = surface_material(stl, "left");
        CHECK(m && m->albedo.r == RAD_DEFAULT_ALBEDO && m->emission.r == 0);
        rad_error error;
        for (int f = 0; f < 6; f++) {
            const material_values *v = material_named(box[f].material);
            rad_rgb albedo = {v->albedo[0], v->albedo[1], v->albedo[2]};
            rad_rgb emission = {v->emission[0], v->emission[1], v->emission[2]};
            CHECK(rad_scene_set_material(stl, box[f].name, &albedo, &emission, &error) == RAD_OK);
        }
        check_box_materials(stl);
        if (solve_faces("box.stl", stl, got))
            compare_faces("box.stl", got, reference);
        /* an unknown name is an error naming it */
        rad_rgb grey = {0.5, 0.5, 0.5};
        CHECK(rad_scene_set_material(stl, "ceilling", &grey, NULL, &error) == RAD_ERR_INVALID);
        CHECK(strstr(error.message, "'ceilling'") != NULL);
        rad_scene_destroy(stl);
    }
}

/* Writes test_path(name) from the OBJ through Assimp's exporter `format`. */
static bool export_obj(const char *format, const char *name)
{
    const struct aiScene *scene = aiImportFile(test_path("box.obj"), 0);
    struct aiScene *copy = NULL;
    bool ok = false;
    if (scene) {
        aiCopyScene(scene, &copy); /* Assimp 5.2 cannot export the imported scene itself */
        ok = copy && aiExportScene(copy, format, test_path(name), 0) == aiReturn_SUCCESS;
        aiFreeScene(copy);
        aiReleaseImport(scene);
    }
    if (!ok)
        test_fail(__FILE__, __LINE__, "cannot export %s", name);
    return ok;
}

/* Replaces the first "key, ...value" line's last number in an FBX text. */
static void set_fbx_property(const char *name, const char *key, const char *value)
{
    static char text[1 << 20];
    FILE *file = fopen(test_path(name), "rb");
    size_t size = file ? fread(text, 1, sizeof(text) - 1, file) : 0;
    if (file)
        fclose(file);
    text[size] = 0;
    char *line = strstr(text, key), *end = line ? strchr(line, '\n') : NULL;
    char *comma = line && end ? end : NULL;
    while (comma && comma > line && *comma != ',')
        comma--;
    if (!comma || comma == line) {
        test_fail(__FILE__, __LINE__, "%s: no %s", name, key);
        return;
    }
    file = fopen(test_path(name), "wb");
    if (!file)
        return;
    fwrite(text, 1, (size_t)(comma + 1 - text), file);
    fprintf(file, " %s", value);
    fwrite(end, 1, size - (size_t)(end - text), file);
    fclose(file);
}

static void exported_formats(void)
{
    rad_rgb reference[6], got[6];
    rad_scene *obj = test_load_scene("box.obj");
    if (!obj || !solve_faces("box.obj", obj, reference)) {
        rad_scene_destroy(obj);
        return;
    }
    rad_scene_destroy(obj);
    /* Assimp's 3DS round trip turns the box a quarter turn about x: same faces, moved */
    const char *formats[2][2] = {{"collada", "box.dae"}, {"3ds", "box.3ds"}};
    for (int k = 0; k < 2; k++) {
        if (!export_obj(formats[k][0], formats[k][1]))
            continue;
        rad_scene *scene = test_load_scene(formats[k][1]);
        if (scene && k == 0)
            CHECK(scene->unit_metres == 1); /* Collada: metres unless it says otherwise */
        if (scene && solve_faces(formats[k][1], scene, got)) {
            if (k == 0)
                compare_faces(formats[k][1], got, reference);
            else
                compare_faces_turned(formats[k][1], got, reference);
        }
        rad_scene_destroy(scene);
    }
    /* Collada in centimetres, z up: Assimp scales and turns it into y-up metres, so the
     * unit box is 1 cm on a side; the file's z becomes y (its back, z = 1, at y = 0.01)
     * and its y becomes -z (its ceiling, y = 1, at z = -0.01) */
    const char *dae = test_read_text(test_path("box.dae"));
    const char *unit = strstr(dae, "<unit "), *unit_end = unit ? strstr(unit, "/>") : NULL;
    const char *up = strstr(dae, "<up_axis>Y_UP</up_axis>");
    CHECK(unit && unit_end && up && unit < up);
    if (unit && unit_end && up && unit < up) {
        FILE *file = fopen(test_path("box-cm.dae"), "wb");
        if (file) {
            fwrite(dae, 1, (size_t)(unit - dae), file);
            fputs("<unit name=\"centimeter\" meter=\"0.01\"/>", file);
            fwrite(unit_end + 2, 1, (size_t)(up - unit_end - 2), file);
            fputs("<up_axis>Z_UP</up_axis>", file);
            fputs(up + strlen("<up_axis>Y_UP</up_axis>"), file);
            fclose(file);
        }
        rad_scene *cm = test_load_scene("box-cm.dae");
        if (cm) {
            CHECK(cm->unit_metres == 1);
            CHECK(cm->up.y == 1);
            CHECK_NEAR(rad_scene_area(cm), 6e-4, 1e-6); /* Assimp holds floats */
            for (uint32_t s = 0; s < cm->surface_count; s++) {
                const rad_triangle *t = &cm->triangles[cm->surfaces[s].first_triangle];
                for (int c = 0; c < 3; c++) {
                    if (strcmp(cm->surfaces[s].name, "back") == 0)
                        CHECK_NEAR(cm->positions[t->vertex[c]].y, 0.01, 1e-6);
                    if (strcmp(cm->surfaces[s].name, "ceiling") == 0)
                        CHECK_NEAR(cm->positions[t->vertex[c]].z, -0.01, 1e-6);
                }
            }
            rad_scene_destroy(cm);
        }
    }

    /* FBX (ASCII): z up, metres (100 cm per unit); Assimp's FBX round trip loses Ke, which
     * the material's name sets again */
    if (!export_obj("fbxa", "box.fbx"))
        return;
    set_fbx_property("box.fbx", "\"UpAxis\"", "2");
    set_fbx_property("box.fbx", "\"UnitScaleFactor\"", "100");
    rad_scene *fbx = test_load_scene("box.fbx");
    if (!fbx)
        return;
    CHECK(fbx->up.x == 0 && fbx->up.y == 0 && fbx->up.z == 1);
    CHECK_NEAR(fbx->unit_metres, 1, 1e-12);
    rad_camera camera = rad_scene_default_camera(fbx);
    CHECK(camera.up.z == 1 && camera.eye.y < 0 && camera.target.y == 0.5);
    rad_error error;
    rad_rgb lamp = {4, 4, 4};
    CHECK(rad_scene_set_material(fbx, "lamp", NULL, &lamp, &error) == RAD_OK);
    if (solve_faces("box.fbx", fbx, got))
        compare_faces("box.fbx", got, reference);
    rad_scene_destroy(fbx);
}

/* An open box (no ceiling), one material: as OBJ with its MTL, and as plain PLY whose one
 * surface is named after the file and gets the material through set_material. */
static void ply_matches_obj(void)
{
    test_write_file("open.mtl", "newmtl glow\nKd 0.5 0.5 0.5\nKe 1 1 1\n");
    FILE *obj = open_scratch("open.obj");
    FILE *ply = open_scratch("open.ply");
    fprintf(obj, "mtllib open.mtl\no open\nusemtl glow\n");
    fprintf(ply, "ply\nformat ascii 1.0\nelement vertex 20\nproperty float x\nproperty float y\n"
                 "property float z\nelement face 10\nproperty list uchar int vertex_indices\n"
                 "end_header\n");
    for (int f = 0; f < 6; f++) {
        if (f == 1)
            continue; /* the ceiling */
        for (int k = 0; k < 4; k++) {
            fprintf(obj, "v %g %g %g\n", box[f].corner[k][0], box[f].corner[k][1],
                    box[f].corner[k][2]);
            fprintf(ply, "%g %g %g\n", box[f].corner[k][0], box[f].corner[k][1],
                    box[f].corner[k][2]);
        }
    }
    for (int f = 0; f < 5; f++) {
        fprintf(obj, "f %d %d %d\nf %d %d %d\n", 4 * f + 1, 4 * f + 2, 4 * f + 3, 4 * f + 1,
                4 * f + 3, 4 * f + 4);
        fprintf(ply, "3 %d %d %d\n3 %d %d %d\n", 4 * f, 4 * f + 1, 4 * f + 2, 4 * f, 4 * f + 2,
                4 * f + 3);
    }
    fclose(obj);
    fclose(ply);
    rad_rgb reference[6], got[6];
    rad_scene *a = test_load_scene("open.obj"), *b = test_load_scene("open.ply");
    if (a && b && solve_faces("open.obj", a, reference)) {
        CHECK(b->surface_count == 1 && strcmp(b->surfaces[0].name, "open") == 0);
        CHECK(b->materials[b->triangles[0].material].albedo.g == RAD_DEFAULT_ALBEDO);
        CHECK(!rad_scene_has_emitter(b));
        rad_error error;
        rad_rgb albedo = {0.5, 0.5, 0.5}, emission = {1, 1, 1};
        CHECK(rad_scene_set_material(b, "open", &albedo, &emission, &error) == RAD_OK);
        /* the open box loses light through its top: the floor sees most of it, so it
         * keeps less than the closed-furnace value 2 pi, and more than its own pi */
        CHECK(reference[2].r < 2 * 3.14159265 && reference[2].r > 3.14159265);
        if (solve_faces("open.ply", b, got))
            compare_faces("open.ply", got, reference);
    }
    rad_scene_destroy(a);
    rad_scene_destroy(b);
}

/* Emitted radiance = emissiveFactor x emissiveStrength, numerically, through Assimp's
 * renumbering: materials are used in reverse file order and the first is unused. */
static void emissive_strength(void)
{
    unsigned char bin[512];
    size_t length = gltf_buffer(bin);
    char uri[1024] = "data:application/octet-stream;base64,";
    static const char digits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    size_t n = strlen(uri);
    for (size_t k = 0; k < length; k += 3) {
        uint32_t v = (uint32_t)bin[k] << 16 | (k + 1 < length ? (uint32_t)bin[k + 1] << 8 : 0) |
                     (k + 2 < length ? bin[k + 2] : 0);
        uri[n++] = digits[v >> 18 & 63];
        uri[n++] = digits[v >> 12 & 63];
        uri[n++] = k + 1 < length ? digits[v >> 6 & 63] : '=';
        uri[n++] = k + 2 < length ? digits[v & 63] : '=';
    }
    uri[n] = 0;
    char json[8192];
    snprintf(json, sizeof(json),
             "{\"asset\":{\"version\":\"2.0\"},\"scenes\":[{\"nodes\":[0,1,2]}],"
             "\"nodes\":[{\"mesh\":0},{\"mesh\":1},{\"camera\":0,\"translation\":[0.5,0.5,3],"
             "\"name\":\"eye\"}],"
             "\"cameras\":[{\"type\":\"perspective\",\"perspective\":{\"yfov\":0.5,"
             "\"aspectRatio\":1.5,\"znear\":0.01}}],"
             "\"meshes\":[{\"name\":\"a\",\"primitives\":[{\"attributes\":{\"POSITION\":0},"
             "\"indices\":2,\"material\":2}]},"
             "{\"name\":\"b\",\"primitives\":[{\"attributes\":{\"POSITION\":1},\"indices\":2,"
             "\"material\":1}]}],"
             "\"materials\":[{\"name\":\"x\",\"emissiveFactor\":[1,1,1],\"extensions\":"
             "{\"KHR_materials_emissive_strength\":{\"emissiveStrength\":50}}},"
             "{\"name\":\"plain\",\"emissiveFactor\":[0.2,0.3,0.4]},"
             "{\"name\":\"strong\",\"emissiveFactor\":[1,0.5,0.25],\"extensions\":"
             "{\"KHR_materials_emissive_strength\":{\"emissiveStrength\":6}}}],"
             "\"buffers\":[{\"byteLength\":%zu,\"uri\":\"%s\"}],"
             "\"bufferViews\":[{\"buffer\":0,\"byteLength\":288},"
             "{\"buffer\":0,\"byteOffset\":288,\"byteLength\":12}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":"
             "\"VEC3\",\"min\":[0,0,0],\"max\":[1,0,1]},{\"bufferView\":0,\"byteOffset\":48,"
             "\"componentType\":5126,\"count\":4,\"type\":\"VEC3\",\"min\":[0,1,0],\"max\":"
             "[1,1,1]},{\"bufferView\":1,\"componentType\":5123,\"count\":6,"
             "\"type\":\"SCALAR\"}]}",
             length, uri);
    test_write_file("strength.gltf", json);
    rad_scene *scene = test_load_scene("strength.gltf");
    if (!scene)
        return;
    const rad_material *a = surface_material(scene, "a"), *b = surface_material(scene, "b");
    if (a && b) {
        CHECK(strcmp(a->name, "strong") == 0);
        CHECK_NEAR(a->emission.r, 6, 1e-6);
        CHECK_NEAR(a->emission.g, 3, 1e-6);
        CHECK_NEAR(a->emission.b, 1.5, 1e-6);
        CHECK(strcmp(b->name, "plain") == 0);
        CHECK_NEAR(b->emission.r, 0.2, 1e-6);
        CHECK_NEAR(b->emission.b, 0.4, 1e-6);
    }
    /* the camera at its node, looking down -z, vertical fov = yfov = 0.5 rad */
    CHECK(scene->has_camera);
    CHECK_NEAR(scene->camera.eye.z, 3, 1e-9);
    CHECK_NEAR(scene->camera.target.z, 2, 1e-9);
    CHECK_NEAR(scene->camera.fov_degrees, 0.5 * 180 / 3.14159265358979, 1e-6);
    rad_scene_destroy(scene);
}

/* The two Cornell box files: the standard one renders lit; the one from the wild has no
 * Ke (its light's power sits in Ka), so it is dark until --emit names the light. */
static void cornell_files(void)
{
    /* the reference files are part of the project (../shared): missing is a failure */
    const char *references[] = {RAD_SHARED_DIR "/scenes/cornell-box.obj",
                                RAD_SHARED_DIR "/scenes/cornell-box.mtl",
                                RAD_SHARED_DIR "/scenes/wild/cornell_box.obj"};
    for (size_t k = 0; k < sizeof(references) / sizeof(references[0]); k++)
        if (!test_file_exists(references[k])) {
            test_fail(__FILE__, __LINE__, "reference scene %s is missing", references[k]);
            return;
        }
    int code = test_run_tool("render " RAD_SHARED_DIR "/scenes/cornell-box.obj -o std.pfm "
                             "--size 24x24 --patch-size 100");
    CHECK(code == 0);
    code = test_run_tool("render " RAD_SHARED_DIR "/scenes/wild/cornell_box.obj -o wild.pfm "
                         "--size 24x24 --patch-size 100 --emit light=17,12,4 "
                         "--albedo white=0.725,0.71,0.68");
    CHECK(code == 0);
    const char *names[2] = {"std.pfm", "wild.pfm"};
    for (int k = 0; k < 2; k++) {
        rad_image *image = NULL;
        rad_error error;
        CHECK(rad_image_read(test_path(names[k]), &image, &error) == RAD_OK);
        if (!image)
            continue;
        double sum = 0;
        for (size_t p = 0; p < (size_t)image->width * image->height * 3; p++)
            sum += image->rgb[p];
        CHECK(sum > 0);
        rad_image_destroy(image);
    }
    code = test_run_tool("info " RAD_SHARED_DIR "/scenes/wild/cornell_box.obj "
                         "--emit light=17,12,4");
    CHECK(code == 0);
    const char *out = test_read_text(test_path("stdout.txt"));
    CHECK(strstr(out, "emitters: 1") != NULL);
    CHECK(strstr(out, "radiance (17, 12, 4)") != NULL);
}

int main(void)
{
    test_tmpdir();
    same_solution_in_every_format();
    exported_formats();
    ply_matches_obj();
    emissive_strength();
    cornell_files();
    return test_finish("test_formats");
}
