/*
 * lit_mesh_glb.c - the lit mesh as binary glTF 2.0 (.glb): Blender, three.js, any viewer.
 *
 * One mesh, one indexed triangle primitive. Attributes, each a float VEC3 in its own
 * buffer view: POSITION (with the min/max glTF requires), NORMAL (unit), COLOR_0 and
 * _RADIANCE. glTF defines vertex colours as linear and viewers apply the sRGB curve when
 * they display, so COLOR_0 holds the display colour *before* the sRGB curve (radiance x
 * exposure, clamped): a viewer then shows exactly the 8-bit colours of the .ply. _RADIANCE
 * (an application attribute: glTF lets names starting with an underscore through) holds
 * the linear radiance; when the mesh has it, _ILLUMINANCE (float VEC3, likewise) the
 * illuminance. The material is unlit (KHR_materials_unlit), so viewers show the
 * colours instead of shading them a second time. The JSON is built with cJSON.
 *
 * Layout: 12-byte header, JSON chunk padded with spaces to 4 bytes, BIN chunk; every
 * buffer view is a multiple of 4 bytes long, so every offset is 4-aligned.
 */
#include <errno.h>
#include <math.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "core/bytes.h"
#include "core/error.h"
#include "lit_mesh/lit_mesh.h"

#define GLB_MAGIC 0x46546C67u      /* "glTF" */
#define GLB_CHUNK_JSON 0x4E4F534Au /* "JSON" */
#define GLB_CHUNK_BIN 0x004E4942u  /* "BIN\0" */
#define GL_FLOAT 5126
#define GL_UNSIGNED_INT 5125
#define GL_ARRAY_BUFFER 34962
#define GL_ELEMENT_ARRAY_BUFFER 34963

/* Buffer views (and accessors, one each, same index): the vertex attributes, then the
 * indices. */
enum { VIEW_POSITION, VIEW_NORMAL, VIEW_COLOUR, VIEW_RADIANCE, VIEW_ILLUMINANCE };

/* How many vertex attributes the mesh has: the indices' view comes after them. */
static int vertex_views(const lit_mesh *mesh)
{
    return mesh->illuminance ? VIEW_ILLUMINANCE + 1 : VIEW_RADIANCE + 1;
}

/* Adds a buffer view of `length` bytes at `offset` in buffer 0. */
static void add_view(cJSON *views, size_t offset, size_t length, int target)
{
    cJSON *view = cJSON_CreateObject();
    cJSON_AddNumberToObject(view, "buffer", 0);
    cJSON_AddNumberToObject(view, "byteOffset", (double)offset);
    cJSON_AddNumberToObject(view, "byteLength", (double)length);
    cJSON_AddNumberToObject(view, "target", target);
    cJSON_AddItemToArray(views, view);
}

static cJSON *add_accessor(cJSON *accessors, int view, int component, uint32_t count,
                           const char *type)
{
    cJSON *accessor = cJSON_CreateObject();
    cJSON_AddNumberToObject(accessor, "bufferView", view);
    cJSON_AddNumberToObject(accessor, "componentType", component);
    cJSON_AddNumberToObject(accessor, "count", count);
    cJSON_AddStringToObject(accessor, "type", type);
    cJSON_AddItemToArray(accessors, accessor);
    return accessor;
}

static cJSON *float_triple(const float v[3])
{
    double d[3] = {v[0], v[1], v[2]};
    return cJSON_CreateDoubleArray(d, 3);
}

/* The JSON document; NULL when cJSON runs out of memory. */
static char *glb_json(const lit_mesh *mesh, size_t vertex_view, size_t index_view)
{
    /* POSITION's bounds, of the float values actually stored (the validator compares) */
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t v = 0; v < mesh->vertex_count; v++) {
        float p[3] = {(float)mesh->position[v].x, (float)mesh->position[v].y,
                      (float)mesh->position[v].z};
        for (int k = 0; k < 3; k++) {
            lo[k] = fminf(lo[k], p[k]);
            hi[k] = fmaxf(hi[k], p[k]);
        }
    }
    char colour[256];
    lit_mesh_describe_colour(mesh, colour, sizeof(colour));

    cJSON *root = cJSON_CreateObject();
    cJSON *asset = cJSON_AddObjectToObject(root, "asset");
    cJSON_AddStringToObject(asset, "version", "2.0");
    cJSON_AddStringToObject(asset, "generator", "radiosity");
    cJSON *extras = cJSON_AddObjectToObject(asset, "extras");
    cJSON_AddStringToObject(extras, "COLOR_0", colour);
    cJSON_AddStringToObject(extras, "_RADIANCE", "linear radiance, unit of the emitters' Ke");
    if (mesh->illuminance)
        cJSON_AddStringToObject(extras, "_ILLUMINANCE",
                                "illuminance (irradiance), lux with lights in candela and lux");
    cJSON_AddNumberToObject(extras, "exposure_scale", mesh->scale);
    cJSON_AddItemToObject(root, "extensionsUsed", cJSON_CreateStringArray(
                                                      (const char *[]){"KHR_materials_unlit"}, 1));
    cJSON_AddNumberToObject(root, "scene", 0);
    cJSON *scene = cJSON_CreateObject();
    cJSON_AddItemToObject(scene, "nodes", cJSON_CreateIntArray((const int[]){0}, 1));
    cJSON_AddItemToArray(cJSON_AddArrayToObject(root, "scenes"), scene);
    cJSON *node = cJSON_CreateObject();
    cJSON_AddStringToObject(node, "name", "radiosity lit mesh");
    cJSON_AddNumberToObject(node, "mesh", 0);
    cJSON_AddItemToArray(cJSON_AddArrayToObject(root, "nodes"), node);

    cJSON *material = cJSON_CreateObject();
    cJSON_AddStringToObject(material, "name", "radiosity (unlit: vertex colours as they are)");
    cJSON *pbr = cJSON_AddObjectToObject(material, "pbrMetallicRoughness");
    cJSON_AddItemToObject(pbr, "baseColorFactor", cJSON_CreateDoubleArray((const double[]){1, 1, 1, 1}, 4));
    cJSON_AddNumberToObject(pbr, "metallicFactor", 0);
    cJSON_AddNumberToObject(pbr, "roughnessFactor", 1);
    cJSON_AddObjectToObject(cJSON_AddObjectToObject(material, "extensions"), "KHR_materials_unlit");
    cJSON_AddItemToArray(cJSON_AddArrayToObject(root, "materials"), material);

    cJSON *primitive = cJSON_CreateObject();
    cJSON *attributes = cJSON_AddObjectToObject(primitive, "attributes");
    cJSON_AddNumberToObject(attributes, "POSITION", VIEW_POSITION);
    cJSON_AddNumberToObject(attributes, "NORMAL", VIEW_NORMAL);
    cJSON_AddNumberToObject(attributes, "COLOR_0", VIEW_COLOUR);
    cJSON_AddNumberToObject(attributes, "_RADIANCE", VIEW_RADIANCE);
    if (mesh->illuminance)
        cJSON_AddNumberToObject(attributes, "_ILLUMINANCE", VIEW_ILLUMINANCE);
    int indices = vertex_views(mesh);
    cJSON_AddNumberToObject(primitive, "indices", indices);
    cJSON_AddNumberToObject(primitive, "material", 0);
    cJSON_AddNumberToObject(primitive, "mode", 4); /* triangles */
    cJSON *gltf_mesh = cJSON_CreateObject();
    cJSON_AddStringToObject(gltf_mesh, "name", "radiosity lit mesh");
    cJSON_AddItemToArray(cJSON_AddArrayToObject(gltf_mesh, "primitives"), primitive);
    cJSON_AddItemToArray(cJSON_AddArrayToObject(root, "meshes"), gltf_mesh);

    /* accessor k reads buffer view k */
    cJSON *accessors = cJSON_AddArrayToObject(root, "accessors");
    cJSON *position = add_accessor(accessors, VIEW_POSITION, GL_FLOAT, mesh->vertex_count, "VEC3");
    cJSON_AddItemToObject(position, "min", float_triple(lo));
    cJSON_AddItemToObject(position, "max", float_triple(hi));
    add_accessor(accessors, VIEW_NORMAL, GL_FLOAT, mesh->vertex_count, "VEC3");
    add_accessor(accessors, VIEW_COLOUR, GL_FLOAT, mesh->vertex_count, "VEC3");
    add_accessor(accessors, VIEW_RADIANCE, GL_FLOAT, mesh->vertex_count, "VEC3");
    if (mesh->illuminance)
        add_accessor(accessors, VIEW_ILLUMINANCE, GL_FLOAT, mesh->vertex_count, "VEC3");
    add_accessor(accessors, indices, GL_UNSIGNED_INT, 3 * mesh->triangle_count, "SCALAR");

    cJSON *views = cJSON_AddArrayToObject(root, "bufferViews");
    for (int k = VIEW_POSITION; k < indices; k++)
        add_view(views, (size_t)k * vertex_view, vertex_view, GL_ARRAY_BUFFER);
    add_view(views, (size_t)indices * vertex_view, index_view, GL_ELEMENT_ARRAY_BUFFER);
    cJSON *buffer = cJSON_CreateObject();
    cJSON_AddNumberToObject(buffer, "byteLength",
                            (double)((size_t)indices * vertex_view + index_view));
    cJSON_AddItemToArray(cJSON_AddArrayToObject(root, "buffers"), buffer);

    char *text = cJSON_PrintUnformatted(root); /* NULL if any step above ran out of memory */
    cJSON_Delete(root);
    return text;
}

static bool put_u32(FILE *stream, uint32_t value)
{
    uint8_t b[4];
    bytes_put_u32(b, value);
    return fwrite(b, sizeof(b), 1, stream) == 1;
}

static bool put_float_triple(FILE *stream, double x, double y, double z)
{
    uint8_t b[12];
    bytes_put_f32(b, (float)x);
    bytes_put_f32(b + 4, (float)y);
    bytes_put_f32(b + 8, (float)z);
    return fwrite(b, sizeof(b), 1, stream) == 1;
}

static bool put_vec3s(FILE *stream, const rad_vec3 *v, uint32_t count)
{
    for (uint32_t k = 0; k < count; k++)
        if (!put_float_triple(stream, v[k].x, v[k].y, v[k].z))
            return false;
    return true;
}

static bool put_rgbs(FILE *stream, const rad_rgb *c, uint32_t count)
{
    for (uint32_t k = 0; k < count; k++)
        if (!put_float_triple(stream, c[k].r, c[k].g, c[k].b))
            return false;
    return true;
}

rad_status lit_mesh_write_glb(const lit_mesh *mesh, FILE *stream, const char *path,
                              rad_error *error)
{
    if (mesh->vertex_count == 0 || mesh->triangle_count == 0)
        return rad_fail(error, RAD_ERR_INVALID, "%s: the mesh is empty", path);
    size_t vertex_view = (size_t)mesh->vertex_count * 12;
    size_t index_view = (size_t)mesh->triangle_count * 12;
    size_t bin_length = (size_t)vertex_views(mesh) * vertex_view + index_view;
    char *json = glb_json(mesh, vertex_view, index_view);
    if (!json)
        return rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory for the glTF JSON", path);
    size_t json_length = strlen(json);
    size_t json_padded = (json_length + 3) & ~(size_t)3;
    size_t total = 12 + 8 + json_padded + 8 + bin_length;
    if (total > UINT32_MAX) {
        cJSON_free(json);
        return rad_fail(error, RAD_ERR_INVALID, "%s: %zu bytes: larger than a .glb can be (4 GB)",
                        path, total);
    }
    bool ok = put_u32(stream, GLB_MAGIC) && put_u32(stream, 2) && put_u32(stream, (uint32_t)total) &&
              put_u32(stream, (uint32_t)json_padded) && put_u32(stream, GLB_CHUNK_JSON) &&
              fwrite(json, 1, json_length, stream) == json_length &&
              fwrite("   ", 1, json_padded - json_length, stream) == json_padded - json_length &&
              put_u32(stream, (uint32_t)bin_length) && put_u32(stream, GLB_CHUNK_BIN);
    cJSON_free(json);
    ok = ok && put_vec3s(stream, mesh->position, mesh->vertex_count) &&
         put_vec3s(stream, mesh->normal, mesh->vertex_count) &&
         put_rgbs(stream, mesh->display, mesh->vertex_count) &&
         put_rgbs(stream, mesh->radiance, mesh->vertex_count) &&
         (!mesh->illuminance || put_rgbs(stream, mesh->illuminance, mesh->vertex_count));
    for (uint32_t t = 0; ok && t < mesh->triangle_count; t++)
        ok = put_u32(stream, mesh->triangles[t][0]) && put_u32(stream, mesh->triangles[t][1]) &&
             put_u32(stream, mesh->triangles[t][2]);
    if (!ok)
        return rad_fail(error, RAD_ERR_IO, "%s: write failed: %s", path, strerror(errno));
    return RAD_OK;
}
