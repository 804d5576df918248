/*
 * gltf_json.c - see gltf_json.h. Parses the JSON with cJSON (Debian's libcjson); for a
 * .glb, the JSON is the container's first chunk.
 *
 * The checks run before Assimp sees the file, so that a user reads one clear line naming
 * the file: a .glb shorter than its header says, a buffer whose file is missing or short,
 * and references (accessor, buffer view, buffer, material, mesh, node) beyond their arrays
 * or byte ranges beyond their buffers, which Assimp 5.2 does not all check.
 *
 * Lights (KHR_lights_punctual) are read here rather than from Assimp's aiLight: Assimp
 * 5.2 stores glTF's cone half-angles where aiLight means full angles, and places the light
 * by its node name only. Each node of the default scene that holds a light gives one,
 * placed by the product of the node transforms from its root, in double precision.
 */
#include "scene/gltf_json.h"

#include <cjson/cJSON.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

#include "core/alloc.h"
#include "core/error.h"
#include "core/vec3.h"

enum {
    GLB_MAGIC = 0x46546C67u, /* "glTF" */
    GLB_CHUNK_JSON = 0x4E4F534Au,
    GLB_CHUNK_BIN = 0x004E4942u
};

static uint32_t read_u32(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

/* The whole file, NUL-terminated. */
static rad_status read_whole(const char *path, unsigned char **data, size_t *size,
                             rad_error *error)
{
    FILE *file = fopen(path, "rb");
    if (!file)
        return rad_fail(error, RAD_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    struct stat st;
    if (fstat(fileno(file), &st) != 0 || st.st_size < 0) {
        fclose(file);
        return rad_fail(error, RAD_ERR_IO, "%s: cannot read", path);
    }
    *size = (size_t)st.st_size;
    *data = rad_alloc_array(*size + 1, 1);
    if (!*data) {
        fclose(file);
        return rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory", path);
    }
    size_t got = fread(*data, 1, *size, file);
    fclose(file);
    if (got != *size) {
        free(*data);
        *data = NULL;
        return rad_fail(error, RAD_ERR_IO, "%s: cannot read", path);
    }
    (*data)[*size] = 0;
    return RAD_OK;
}

/* Checks a .glb container; points at its JSON chunk and tells the BIN chunk's size. */
static rad_status open_glb(const char *path, unsigned char *data, size_t size,
                           const char **json, size_t *json_size, size_t *bin_size,
                           rad_error *error)
{
    if (size < 20 || read_u32(data) != GLB_MAGIC)
        return rad_fail(error, RAD_ERR_PARSE, "%s: not a binary glTF file (no glTF header)",
                        path);
    if (read_u32(data + 4) != 2)
        return rad_fail(error, RAD_ERR_UNSUPPORTED, "%s: binary glTF version %u (only 2 is read)",
                        path, read_u32(data + 4));
    uint32_t length = read_u32(data + 8);
    if (length > size)
        return rad_fail(error, RAD_ERR_PARSE,
                        "%s: truncated: the glb header says %u bytes, the file has %zu", path,
                        length, size);
    uint32_t chunk = read_u32(data + 12);
    if (read_u32(data + 16) != GLB_CHUNK_JSON || chunk > length - 20)
        return rad_fail(error, RAD_ERR_PARSE, "%s: the first glb chunk is not a whole JSON chunk",
                        path);
    *json = (const char *)data + 20;
    *json_size = chunk;
    *bin_size = 0;
    size_t next = 20 + (size_t)chunk;
    if (next + 8 <= length && read_u32(data + next + 4) == GLB_CHUNK_BIN) {
        uint32_t bin = read_u32(data + next);
        if (bin > length - next - 8)
            return rad_fail(error, RAD_ERR_PARSE, "%s: truncated: the binary chunk says %u bytes",
                            path, bin);
        *bin_size = bin;
    }
    return RAD_OK;
}

static double number_or(const cJSON *object, const char *key, double fallback)
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(object, key);
    return cJSON_IsNumber(item) ? item->valuedouble : fallback;
}

static void read_vector(const cJSON *object, const char *key, double *out, int count)
{
    const cJSON *array = cJSON_GetObjectItemCaseSensitive(object, key);
    if (!cJSON_IsArray(array))
        return;
    for (int k = 0; k < count; k++) {
        const cJSON *item = cJSON_GetArrayItem(array, k);
        if (cJSON_IsNumber(item))
            out[k] = item->valuedouble;
    }
}

static int array_size(const cJSON *root, const char *key)
{
    const cJSON *array = cJSON_GetObjectItemCaseSensitive(root, key);
    return cJSON_IsArray(array) ? cJSON_GetArraySize(array) : 0;
}

/* An index member: -1 when absent, -2 when present but not an index in [0, limit). */
static int index_member(const cJSON *object, const char *key, int limit)
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(object, key);
    if (!item)
        return -1;
    if (!cJSON_IsNumber(item) || item->valuedouble < 0 || item->valuedouble >= limit ||
        item->valuedouble != (double)(int)item->valuedouble)
        return -2;
    return (int)item->valuedouble;
}

/* A URI's path part with %XX escapes decoded, appended to the glTF file's folder. */
static void uri_to_path(const char *gltf_path, const char *uri, char *out, size_t size)
{
    const char *slash = strrchr(gltf_path, '/');
    size_t n = slash ? (size_t)(slash - gltf_path) + 1 : 0;
    if (n >= size)
        n = size - 1;
    memcpy(out, gltf_path, n);
    for (; *uri && n + 1 < size; uri++) {
        unsigned value;
        if (uri[0] == '%' && sscanf(uri + 1, "%2x", &value) == 1 && uri[1] && uri[2]) {
            out[n++] = (char)value;
            uri += 2;
        } else {
            out[n++] = *uri;
        }
    }
    out[n] = 0;
}

static const size_t component_bytes[] = {[5120 - 5120] = 1, [5121 - 5120] = 1, [5122 - 5120] = 2,
                                         [5123 - 5120] = 2, [5125 - 5120] = 4, [5126 - 5120] = 4};

static size_t type_components(const char *type)
{
    static const struct { const char *name; size_t count; } types[] = {
        {"SCALAR", 1}, {"VEC2", 2}, {"VEC3", 3}, {"VEC4", 4}, {"MAT2", 4}, {"MAT3", 9}, {"MAT4", 16}};
    for (size_t k = 0; k < sizeof(types) / sizeof(types[0]); k++)
        if (strcmp(type, types[k].name) == 0)
            return types[k].count;
    return 0;
}

/* Buffers exist and are long enough, views lie inside their buffers, accessors inside their
 * views. */
static rad_status check_data(const char *path, const cJSON *root, bool is_glb, size_t bin_size,
                             rad_error *error)
{
    const cJSON *buffers = cJSON_GetObjectItemCaseSensitive(root, "buffers");
    const cJSON *views = cJSON_GetObjectItemCaseSensitive(root, "bufferViews");
    const cJSON *accessors = cJSON_GetObjectItemCaseSensitive(root, "accessors");
    int buffer_count = array_size(root, "buffers"), view_count = array_size(root, "bufferViews");
    double *buffer_length = rad_alloc_array((size_t)buffer_count, sizeof(*buffer_length));
    if (!buffer_length)
        return rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory", path);
    rad_status status = RAD_OK;
    for (int b = 0; b < buffer_count && status == RAD_OK; b++) {
        const cJSON *buffer = cJSON_GetArrayItem(buffers, b);
        double length = number_or(buffer, "byteLength", -1);
        const cJSON *uri = cJSON_GetObjectItemCaseSensitive(buffer, "uri");
        buffer_length[b] = length;
        if (!(length >= 0))
            status = rad_fail(error, RAD_ERR_PARSE, "%s: buffer %d has no byteLength", path, b);
        else if (cJSON_IsString(uri) && strncmp(uri->valuestring, "data:", 5) != 0) {
            char file[4096];
            struct stat st;
            uri_to_path(path, uri->valuestring, file, sizeof(file));
            if (stat(file, &st) != 0 || !S_ISREG(st.st_mode))
                status = rad_fail(error, RAD_ERR_IO, "%s: buffer %d: file '%s' not found", path,
                                  b, uri->valuestring);
            else if ((double)st.st_size < length)
                status = rad_fail(error, RAD_ERR_PARSE,
                                  "%s: buffer %d: file '%s' has %lld bytes, %.0f expected", path,
                                  b, uri->valuestring, (long long)st.st_size, length);
        } else if (!uri) {
            if (!is_glb || b != 0)
                status = rad_fail(error, RAD_ERR_PARSE, "%s: buffer %d has no uri", path, b);
            else if ((double)bin_size < length)
                status = rad_fail(error, RAD_ERR_PARSE,
                                  "%s: buffer 0: the binary chunk has %zu bytes, %.0f expected",
                                  path, bin_size, length);
        }
    }
    for (int v = 0; v < view_count && status == RAD_OK; v++) {
        const cJSON *view = cJSON_GetArrayItem(views, v);
        int buffer = index_member(view, "buffer", buffer_count);
        double end = number_or(view, "byteOffset", 0) + number_or(view, "byteLength", -1);
        if (buffer < 0)
            status = rad_fail(error, RAD_ERR_PARSE, "%s: bufferView %d names a buffer out of range",
                              path, v);
        else if (!(end <= buffer_length[buffer]) || number_or(view, "byteLength", -1) < 0)
            status = rad_fail(error, RAD_ERR_PARSE,
                              "%s: bufferView %d reaches past the end of buffer %d", path, v,
                              buffer);
    }
    int accessor_count = array_size(root, "accessors");
    for (int a = 0; a < accessor_count && status == RAD_OK; a++) {
        const cJSON *accessor = cJSON_GetArrayItem(accessors, a);
        int view = index_member(accessor, "bufferView", view_count);
        const cJSON *type = cJSON_GetObjectItemCaseSensitive(accessor, "type");
        double component = number_or(accessor, "componentType", 0);
        double count = number_or(accessor, "count", -1);
        size_t components = cJSON_IsString(type) ? type_components(type->valuestring) : 0;
        if (view == -2) {
            status = rad_fail(error, RAD_ERR_PARSE,
                              "%s: accessor %d names a bufferView out of range", path, a);
            break;
        }
        if (components == 0 || !(count >= 0) || component < 5120 || component > 5126 ||
            component_bytes[(int)component - 5120] == 0) {
            status = rad_fail(error, RAD_ERR_PARSE, "%s: accessor %d: bad type or count", path, a);
            break;
        }
        if (view < 0 || count == 0)
            continue; /* no data: zeros by the specification */
        const cJSON *view_object = cJSON_GetArrayItem(views, view);
        size_t element = components * component_bytes[(int)component - 5120];
        double stride = number_or(view_object, "byteStride", 0);
        if (stride < (double)element)
            stride = (double)element;
        double end = number_or(accessor, "byteOffset", 0) + (count - 1) * stride + (double)element;
        if (end > number_or(view_object, "byteLength", 0))
            status = rad_fail(error, RAD_ERR_PARSE,
                              "%s: accessor %d reaches past the end of bufferView %d", path, a,
                              view);
    }
    free(buffer_length);
    return status;
}

typedef struct walk_state {
    const cJSON *root;
    const char *path;
    uint8_t *node_seen, *mesh_seen, *material_seen;
    int node_count, mesh_count, material_count, accessor_count;
    gltf_info *info;
} walk_state;

static rad_status visit_mesh(walk_state *w, int mesh, rad_error *error)
{
    if (w->mesh_seen[mesh])
        return RAD_OK;
    w->mesh_seen[mesh] = 1;
    const cJSON *object = cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(w->root, "meshes"), mesh);
    const cJSON *primitives = cJSON_GetObjectItemCaseSensitive(object, "primitives");
    int count = cJSON_IsArray(primitives) ? cJSON_GetArraySize(primitives) : 0;
    for (int p = 0; p < count; p++) {
        const cJSON *primitive = cJSON_GetArrayItem(primitives, p);
        const cJSON *attributes = cJSON_GetObjectItemCaseSensitive(primitive, "attributes");
        const cJSON *attribute;
        cJSON_ArrayForEach(attribute, attributes)
        {
            if (!cJSON_IsNumber(attribute) || attribute->valuedouble < 0 ||
                attribute->valuedouble >= w->accessor_count)
                return rad_fail(error, RAD_ERR_PARSE,
                                "%s: mesh %d, primitive %d: attribute %s names an accessor out "
                                "of range",
                                w->path, mesh, p, attribute->string ? attribute->string : "?");
        }
        if (index_member(primitive, "indices", w->accessor_count) == -2)
            return rad_fail(error, RAD_ERR_PARSE,
                            "%s: mesh %d, primitive %d: indices name an accessor out of range",
                            w->path, mesh, p);
        int material = index_member(primitive, "material", w->material_count);
        if (material == -2)
            return rad_fail(error, RAD_ERR_PARSE,
                            "%s: mesh %d, primitive %d names a material out of range", w->path,
                            mesh, p);
        if (material >= 0 && !w->material_seen[material]) {
            w->material_seen[material] = 1;
            w->info->assimp_order[w->info->assimp_count++] = (uint32_t)material;
        }
    }
    return RAD_OK;
}

static rad_status visit_node(walk_state *w, int node, unsigned depth, rad_error *error)
{
    if (w->node_seen[node])
        return RAD_OK;
    if (depth > 256)
        return rad_fail(error, RAD_ERR_PARSE, "%s: node tree deeper than 256", w->path);
    w->node_seen[node] = 1;
    const cJSON *object = cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(w->root, "nodes"), node);
    const cJSON *children = cJSON_GetObjectItemCaseSensitive(object, "children");
    const cJSON *child;
    cJSON_ArrayForEach(child, children)
    {
        if (!cJSON_IsNumber(child) || child->valuedouble < 0 || child->valuedouble >= w->node_count)
            return rad_fail(error, RAD_ERR_PARSE, "%s: node %d names a child out of range",
                            w->path, node);
        rad_status status = visit_node(w, (int)child->valuedouble, depth + 1, error);
        if (status != RAD_OK)
            return status;
    }
    int mesh = index_member(object, "mesh", w->mesh_count);
    if (mesh == -2)
        return rad_fail(error, RAD_ERR_PARSE, "%s: node %d names a mesh out of range", w->path,
                        node);
    return mesh >= 0 ? visit_mesh(w, mesh, error) : RAD_OK;
}

/* Visits the nodes an array of objects names under `key` (a list, or one index). */
static rad_status visit_listed_nodes(walk_state *w, const char *array, const char *key,
                                     const char *inner, rad_error *error)
{
    const cJSON *item;
    cJSON_ArrayForEach(item, cJSON_GetObjectItemCaseSensitive(w->root, array))
    {
        const cJSON *list = cJSON_GetObjectItemCaseSensitive(item, key);
        const cJSON *entry;
        cJSON_ArrayForEach(entry, list)
        {
            const cJSON *target = inner ? cJSON_GetObjectItemCaseSensitive(
                                              cJSON_GetObjectItemCaseSensitive(entry, inner), "node")
                                        : entry;
            if (cJSON_IsNumber(target) && target->valuedouble >= 0 &&
                target->valuedouble < w->node_count) {
                rad_status status = visit_node(w, (int)target->valuedouble, 0, error);
                if (status != RAD_OK)
                    return status;
            }
        }
    }
    return RAD_OK;
}

static rad_status read_materials(const char *path, const cJSON *root, gltf_info *info,
                                 rad_error *error)
{
    const cJSON *materials = cJSON_GetObjectItemCaseSensitive(root, "materials");
    info->material_count = (uint32_t)array_size(root, "materials");
    info->materials = rad_alloc_array(info->material_count, sizeof(*info->materials));
    info->assimp_order = rad_alloc_array(info->material_count, sizeof(*info->assimp_order));
    if (!info->materials || !info->assimp_order)
        return rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory", path);
    for (uint32_t m = 0; m < info->material_count; m++) {
        const cJSON *object = cJSON_GetArrayItem(materials, (int)m);
        gltf_material *material = &info->materials[m];
        const cJSON *name = cJSON_GetObjectItemCaseSensitive(object, "name");
        if (cJSON_IsString(name))
            snprintf(material->name, sizeof(material->name), "%s", name->valuestring);
        for (int c = 0; c < 3; c++)
            material->base_color[c] = 1;
        read_vector(cJSON_GetObjectItemCaseSensitive(object, "pbrMetallicRoughness"),
                    "baseColorFactor", material->base_color, 3);
        read_vector(object, "emissiveFactor", material->emissive_factor, 3);
        const cJSON *extensions = cJSON_GetObjectItemCaseSensitive(object, "extensions");
        material->emissive_strength = number_or(
            cJSON_GetObjectItemCaseSensitive(extensions, "KHR_materials_emissive_strength"),
            "emissiveStrength", 1);
    }
    return RAD_OK;
}

static rad_status walk(const char *path, const cJSON *root, gltf_info *info, rad_error *error)
{
    walk_state w = {root, path, NULL, NULL, NULL, array_size(root, "nodes"),
                    array_size(root, "meshes"), (int)info->material_count,
                    array_size(root, "accessors"), info};
    w.node_seen = rad_alloc_array((size_t)w.node_count, 1);
    w.mesh_seen = rad_alloc_array((size_t)w.mesh_count, 1);
    w.material_seen = rad_alloc_array((size_t)w.material_count, 1);
    rad_status status = RAD_OK;
    if (!w.node_seen || !w.mesh_seen || !w.material_seen) {
        status = rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory", path);
        goto done;
    }
    int scene = index_member(root, "scene", array_size(root, "scenes"));
    if (scene == -2) {
        status = rad_fail(error, RAD_ERR_PARSE, "%s: the default scene is out of range", path);
        goto done;
    }
    const cJSON *nodes = cJSON_GetObjectItemCaseSensitive(
        cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(root, "scenes"), scene < 0 ? 0 : scene),
        "nodes");
    const cJSON *node;
    cJSON_ArrayForEach(node, nodes)
    {
        if (!cJSON_IsNumber(node) || node->valuedouble < 0 || node->valuedouble >= w.node_count) {
            status = rad_fail(error, RAD_ERR_PARSE, "%s: a scene names a node out of range", path);
            goto done;
        }
        status = visit_node(&w, (int)node->valuedouble, 0, error);
        if (status != RAD_OK)
            goto done;
    }
    status = visit_listed_nodes(&w, "skins", "joints", NULL, error);
    if (status == RAD_OK)
        status = visit_listed_nodes(&w, "animations", "channels", "target", error);
done:
    free(w.node_seen);
    free(w.mesh_seen);
    free(w.material_seen);
    return status;
}

/* ---- KHR_lights_punctual (the Khronos extension's README: types, defaults, -Z axis) ---- */

typedef struct matrix4 {
    double m[4][4]; /* [row][column], acting on column vectors */
} matrix4;

static matrix4 matrix_identity(void)
{
    matrix4 r;
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++)
            r.m[i][j] = i == j;
    return r;
}

static matrix4 matrix_product(const matrix4 *a, const matrix4 *b)
{
    matrix4 r;
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++)
            r.m[i][j] = a->m[i][0] * b->m[0][j] + a->m[i][1] * b->m[1][j] +
                        a->m[i][2] * b->m[2][j] + a->m[i][3] * b->m[3][j];
    return r;
}

/* A node's local transform (glTF 2.0, "Transformations"): `matrix`, 16 numbers in
 * column-major order, else T * R * S from translation, rotation (a unit quaternion
 * x, y, z, w; normalised here) and scale. false when `matrix` is not 16 numbers. */
static bool node_matrix(const cJSON *node, matrix4 *out)
{
    double(*m)[4] = out->m;
    const cJSON *matrix = cJSON_GetObjectItemCaseSensitive(node, "matrix");
    if (matrix) {
        if (!cJSON_IsArray(matrix) || cJSON_GetArraySize(matrix) != 16)
            return false;
        for (int k = 0; k < 16; k++) {
            const cJSON *item = cJSON_GetArrayItem(matrix, k);
            if (!cJSON_IsNumber(item))
                return false;
            m[k % 4][k / 4] = item->valuedouble;
        }
        return true;
    }
    double t[3] = {0, 0, 0}, q[4] = {0, 0, 0, 1}, s[3] = {1, 1, 1};
    read_vector(node, "translation", t, 3);
    read_vector(node, "rotation", q, 4);
    read_vector(node, "scale", s, 3);
    double length = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (length > 0)
        for (int k = 0; k < 4; k++)
            q[k] /= length;
    double x = q[0], y = q[1], z = q[2], w = q[3];
    /* the rotation matrix of a unit quaternion */
    double r[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)},
                      {2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)},
                      {2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)}};
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++)
            m[i][j] = r[i][j] * s[j];
        m[i][3] = t[i];
        m[3][i] = 0;
    }
    m[3][3] = 1;
    return true;
}

/* Light `index` of the extension's array, checked, without position and direction: type,
 * intensity = color x intensity, cone half-angles in degrees, its own name (or ""). */
static rad_status read_light(const char *path, const cJSON *object, int index, rad_light *out,
                             bool *ranged, rad_error *error)
{
    memset(out, 0, sizeof(*out));
    const cJSON *type = cJSON_GetObjectItemCaseSensitive(object, "type");
    const char *name = cJSON_IsString(type) ? type->valuestring : "";
    if (strcmp(name, "point") == 0)
        out->type = RAD_LIGHT_POINT;
    else if (strcmp(name, "spot") == 0)
        out->type = RAD_LIGHT_SPOT;
    else if (strcmp(name, "directional") == 0)
        out->type = RAD_LIGHT_DIRECTIONAL;
    else
        return rad_fail(error, RAD_ERR_PARSE,
                        "%s: extensions.KHR_lights_punctual.lights[%d].type '%.40s' is not "
                        "point, spot or directional",
                        path, index, name);
    const cJSON *intensity = cJSON_GetObjectItemCaseSensitive(object, "intensity");
    double value = cJSON_IsNumber(intensity) ? intensity->valuedouble : 1;
    if ((intensity && !cJSON_IsNumber(intensity)) || !(value >= 0) || !isfinite(value))
        return rad_fail(error, RAD_ERR_PARSE,
                        "%s: extensions.KHR_lights_punctual.lights[%d].intensity must be a "
                        "finite number >= 0",
                        path, index);
    double color[3] = {1, 1, 1};
    read_vector(object, "color", color, 3);
    if (!(color[0] >= 0 && color[1] >= 0 && color[2] >= 0) || !isfinite(color[0]) ||
        !isfinite(color[1]) || !isfinite(color[2]))
        return rad_fail(error, RAD_ERR_PARSE,
                        "%s: extensions.KHR_lights_punctual.lights[%d].color must be finite "
                        "and not negative",
                        path, index);
    out->intensity = (rad_rgb){color[0] * value, color[1] * value, color[2] * value};
    if (out->type == RAD_LIGHT_SPOT) {
        const cJSON *spot = cJSON_GetObjectItemCaseSensitive(object, "spot");
        double inner = number_or(spot, "innerConeAngle", 0);
        double outer = number_or(spot, "outerConeAngle", RAD_PI / 4);
        if (!(inner >= 0 && inner <= outer && outer > 0 && outer <= RAD_PI / 2))
            return rad_fail(error, RAD_ERR_PARSE,
                            "%s: extensions.KHR_lights_punctual.lights[%d].spot: cone angles "
                            "inner %g and outer %g rad must satisfy 0 <= inner <= outer <= pi/2 "
                            "and outer > 0",
                            path, index, inner, outer);
        out->inner_degrees = inner * 180 / RAD_PI;
        out->outer_degrees = outer * 180 / RAD_PI;
    }
    const cJSON *light_name = cJSON_GetObjectItemCaseSensitive(object, "name");
    if (cJSON_IsString(light_name))
        snprintf(out->name, sizeof(out->name), "%s", light_name->valuestring);
    *ranged = cJSON_GetObjectItemCaseSensitive(object, "range") != NULL;
    return RAD_OK;
}

typedef struct light_walk {
    const cJSON *nodes;
    const char *path;
    int node_count;
    const rad_light *defined; /* the extension's lights, read_light's part */
    int defined_count;
    const uint8_t *defined_ranged;
    uint8_t *seen;
    gltf_info *info;
} light_walk;

static const cJSON *node_light(const cJSON *node)
{
    const cJSON *extensions = cJSON_GetObjectItemCaseSensitive(node, "extensions");
    return cJSON_GetObjectItemCaseSensitive(
        cJSON_GetObjectItemCaseSensitive(extensions, "KHR_lights_punctual"), "light");
}

/* The light `index` held by `node`, placed by the node's world transform. */
static rad_status place_light(light_walk *w, int node, int index, const matrix4 *world,
                              rad_error *error)
{
    const double(*m)[4] = world->m;
    rad_light light = w->defined[index];
    const cJSON *object = cJSON_GetArrayItem(w->nodes, node);
    const cJSON *node_name = cJSON_GetObjectItemCaseSensitive(object, "name");
    if (!light.name[0] && cJSON_IsString(node_name))
        snprintf(light.name, sizeof(light.name), "%s", node_name->valuestring);
    if (!light.name[0])
        snprintf(light.name, sizeof(light.name), "light %d", index);
    light.position = (rad_vec3){m[0][3], m[1][3], m[2][3]};
    rad_vec3 axis = {-m[0][2], -m[1][2], -m[2][2]}; /* the transformed -Z */
    double length = sqrt(axis.x * axis.x + axis.y * axis.y + axis.z * axis.z);
    bool directed = light.type != RAD_LIGHT_POINT;
    if (!(isfinite(light.position.x) && isfinite(light.position.y) &&
          isfinite(light.position.z)) ||
        (directed && !(length > 0 && isfinite(length))))
        return rad_fail(error, RAD_ERR_PARSE,
                        "%s: nodes[%d] (light '%s'): its transform gives no finite %s", w->path,
                        node, light.name, directed ? "position and direction" : "position");
    if (length > 0 && isfinite(length))
        light.direction = (rad_vec3){axis.x / length, axis.y / length, axis.z / length};
    rad_light *grown = rad_resize_array(w->info->lights, (size_t)w->info->light_count + 1,
                                        sizeof(*grown));
    if (!grown)
        return rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory", w->path);
    w->info->lights = grown;
    w->info->lights[w->info->light_count++] = light;
    if (w->defined_ranged[index] && w->info->ranged_light_count++ == 0)
        snprintf(w->info->ranged_light_name, sizeof(w->info->ranged_light_name), "%s",
                 light.name);
    return RAD_OK;
}

static rad_status place_node_lights(light_walk *w, int node, const matrix4 *parent,
                                    unsigned depth, rad_error *error)
{
    if (w->seen[node])
        return RAD_OK;
    if (depth > 256)
        return rad_fail(error, RAD_ERR_PARSE, "%s: node tree deeper than 256", w->path);
    w->seen[node] = 1;
    const cJSON *object = cJSON_GetArrayItem(w->nodes, node);
    matrix4 local;
    if (!node_matrix(object, &local))
        return rad_fail(error, RAD_ERR_PARSE, "%s: nodes[%d].matrix is not 16 numbers", w->path,
                        node);
    matrix4 world = matrix_product(parent, &local);
    const cJSON *light = node_light(object);
    if (light) {
        rad_status status = place_light(w, node, (int)light->valuedouble, &world, error);
        if (status != RAD_OK)
            return status;
    }
    const cJSON *child;
    cJSON_ArrayForEach(child, cJSON_GetObjectItemCaseSensitive(object, "children"))
    {
        if (!cJSON_IsNumber(child) || child->valuedouble < 0 || child->valuedouble >= w->node_count)
            return rad_fail(error, RAD_ERR_PARSE, "%s: node %d names a child out of range",
                            w->path, node);
        rad_status status = place_node_lights(w, (int)child->valuedouble, &world,
                                                depth + 1, error);
        if (status != RAD_OK)
            return status;
    }
    return RAD_OK;
}

/* The extension's lights, checked, and every node's reference to one; then the lights of
 * the default scene's nodes, placed. */
static rad_status read_lights(const char *path, const cJSON *root, gltf_info *info,
                              rad_error *error)
{
    const cJSON *extension = cJSON_GetObjectItemCaseSensitive(
        cJSON_GetObjectItemCaseSensitive(root, "extensions"), "KHR_lights_punctual");
    const cJSON *lights = cJSON_GetObjectItemCaseSensitive(extension, "lights");
    const cJSON *nodes = cJSON_GetObjectItemCaseSensitive(root, "nodes");
    int light_count = cJSON_IsArray(lights) ? cJSON_GetArraySize(lights) : 0;
    int node_count = array_size(root, "nodes");
    bool referenced = false;
    for (int n = 0; n < node_count; n++) {
        const cJSON *light = node_light(cJSON_GetArrayItem(nodes, n));
        if (!light)
            continue;
        if (!cJSON_IsNumber(light) || light->valuedouble < 0 ||
            light->valuedouble >= light_count ||
            light->valuedouble != (double)(int)light->valuedouble)
            return rad_fail(error, RAD_ERR_PARSE,
                            "%s: nodes[%d].extensions.KHR_lights_punctual.light is not an index "
                            "into the %d lights of extensions.KHR_lights_punctual.lights",
                            path, n, light_count);
        referenced = true;
    }
    if (light_count == 0)
        return RAD_OK;
    light_walk w = {nodes, path, node_count, NULL, light_count, NULL, NULL, info};
    rad_light *defined = rad_alloc_array((size_t)light_count, sizeof(*defined));
    uint8_t *ranged = rad_alloc_array((size_t)light_count, 1);
    w.seen = rad_alloc_array((size_t)node_count + 1, 1);
    rad_status status = RAD_OK;
    if (!defined || !ranged || !w.seen)
        status = rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory", path);
    for (int l = 0; l < light_count && status == RAD_OK; l++) {
        bool has_range = false;
        status = read_light(path, cJSON_GetArrayItem(lights, l), l, &defined[l], &has_range,
                            error);
        ranged[l] = has_range;
    }
    w.defined = defined;
    w.defined_ranged = ranged;
    /* the default scene's roots (walk() has checked them) */
    int scene = index_member(root, "scene", array_size(root, "scenes"));
    const cJSON *roots = cJSON_GetObjectItemCaseSensitive(
        cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(root, "scenes"), scene < 0 ? 0 : scene),
        "nodes");
    matrix4 identity = matrix_identity();
    const cJSON *node;
    if (!referenced || status != RAD_OK)
        roots = NULL;
    cJSON_ArrayForEach(node, roots)
    {
        if (!cJSON_IsNumber(node) || node->valuedouble < 0 || node->valuedouble >= node_count) {
            status = rad_fail(error, RAD_ERR_PARSE, "%s: a scene names a node out of range", path);
            break;
        }
        status = place_node_lights(&w, (int)node->valuedouble, &identity, 0, error);
        if (status != RAD_OK)
            break;
    }
    free(defined);
    free(ranged);
    free(w.seen);
    return status;
}

rad_status gltf_info_read(const char *path, gltf_info *out, rad_error *error)
{
    memset(out, 0, sizeof(*out));
    unsigned char *data = NULL;
    size_t size = 0, json_size, bin_size = 0;
    rad_status status = read_whole(path, &data, &size, error);
    if (status != RAD_OK)
        return status;
    const char *json = (const char *)data;
    json_size = size;
    size_t dot = strlen(path) >= 4 ? strlen(path) - 4 : 0;
    bool is_glb = strcasecmp(path + dot, ".glb") == 0 || (size >= 4 && read_u32(data) == GLB_MAGIC);
    if (is_glb)
        status = open_glb(path, data, size, &json, &json_size, &bin_size, error);
    cJSON *root = NULL;
    if (status == RAD_OK) {
        const char *end = NULL;
        root = cJSON_ParseWithLengthOpts(json, json_size, &end, false);
        if (!cJSON_IsObject(root))
            status = rad_fail(error, RAD_ERR_PARSE, "%s: not glTF: the JSON is malformed near "
                              "byte %td",
                              path, root || !end ? (ptrdiff_t)0 : end - json);
    }
    if (status == RAD_OK) {
        const cJSON *asset = cJSON_GetObjectItemCaseSensitive(root, "asset");
        const cJSON *version = cJSON_GetObjectItemCaseSensitive(asset, "version");
        if (!cJSON_IsString(version))
            status = rad_fail(error, RAD_ERR_PARSE, "%s: not glTF: no asset.version", path);
        else if (strncmp(version->valuestring, "2.", 2) != 0)
            status = rad_fail(error, RAD_ERR_UNSUPPORTED, "%s: glTF version %s (only 2.x is read)",
                              path, version->valuestring);
    }
    if (status == RAD_OK)
        status = check_data(path, root, is_glb, bin_size, error);
    if (status == RAD_OK)
        status = read_materials(path, root, out, error);
    if (status == RAD_OK)
        status = walk(path, root, out, error);
    if (status == RAD_OK)
        status = read_lights(path, root, out, error);
    cJSON_Delete(root);
    free(data);
    if (status != RAD_OK)
        gltf_info_free(out);
    return status;
}

void gltf_info_free(gltf_info *info)
{
    free(info->materials);
    free(info->assimp_order);
    free(info->lights);
    memset(info, 0, sizeof(*info));
}
