/*
 * import_assimp.c - reading scene files through Assimp's C API.
 *
 * Assimp does the parsing. This file only (1) checks, for OBJ files, what Assimp passes
 * over silently and what a user must hear about with a line number: a material library
 * that is not there, and non-finite vertex coordinates; (2) walks Assimp's node tree,
 * applying node transforms, and hands triangles, materials and surface names to the
 * scene builder. A surface is an Assimp mesh name (OBJ `o`/`g`), or its node's name.
 */
#include <assimp/cimport.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <ctype.h>
#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

#include "core/alloc.h"
#include "core/error.h"
#include "scene/scene_builder.h"

static bool has_extension(const char *path, const char *extension)
{
    size_t n = strlen(path), m = strlen(extension);
    return n >= m && strcasecmp(path + n - m, extension) == 0;
}

/* The folder part of path, with a trailing slash, or "" . */
static void folder_of(const char *path, char *folder, size_t size)
{
    const char *slash = strrchr(path, '/');
    size_t n = slash ? (size_t)(slash - path) + 1 : 0;
    if (n >= size)
        n = size - 1;
    memcpy(folder, path, n);
    folder[n] = 0;
}

/* OBJ checks Assimp does not make: material libraries exist, vertex coordinates finite. */
static rad_status check_obj(const char *path, FILE *file, rad_error *error)
{
    char folder[4096];
    folder_of(path, folder, sizeof(folder));
    char line[8192];
    unsigned long number = 0;
    while (fgets(line, sizeof(line), file)) {
        number++;
        char *p = line;
        while (*p == ' ' || *p == '\t')
            p++;
        if (strncmp(p, "mtllib", 6) == 0 && isspace((unsigned char)p[6])) {
            char *name = p + 6;
            while (isspace((unsigned char)*name))
                name++;
            char *end = name + strlen(name);
            while (end > name && isspace((unsigned char)end[-1]))
                *--end = 0;
            char library[8192 + 4096];
            snprintf(library, sizeof(library), "%s%s", name[0] == '/' ? "" : folder, name);
            struct stat st;
            if (stat(library, &st) != 0)
                return rad_fail(error, RAD_ERR_IO, "%s:%lu: material library '%s' not found",
                                path, number, name);
            if (!S_ISREG(st.st_mode))
                return rad_fail(error, RAD_ERR_IO, "%s:%lu: material library '%s' is not a file",
                                path, number, name);
        } else if (p[0] == 'v' && (p[1] == ' ' || p[1] == '\t')) {
            char *cursor = p + 2;
            for (int k = 0; k < 3; k++) {
                char *end;
                double value = strtod(cursor, &end);
                if (end == cursor)
                    break; /* malformed: Assimp reports it */
                if (!isfinite(value))
                    return rad_fail(error, RAD_ERR_PARSE,
                                    "%s:%lu: vertex coordinate is not a finite number", path,
                                    number);
                if (fabs(value) > FLT_MAX)
                    return rad_fail(error, RAD_ERR_PARSE,
                                    "%s:%lu: vertex coordinate %g is beyond single precision",
                                    path, number, value);
                cursor = end;
            }
        }
    }
    return RAD_OK;
}

static rad_rgb material_color(const struct aiMaterial *material, const char *key,
                              unsigned type, unsigned index, rad_rgb fallback)
{
    struct aiColor4D color;
    if (aiGetMaterialColor(material, key, type, index, &color) != aiReturn_SUCCESS)
        return fallback;
    return (rad_rgb){color.r, color.g, color.b};
}

typedef struct import_state {
    const struct aiScene *ai;
    scene_builder *builder;
    uint32_t *material_map; /* Assimp material index -> builder index, UINT32_MAX = not yet */
    const char *path;
} import_state;

static rad_status map_material(import_state *state, unsigned index, uint32_t *out,
                               rad_error *error)
{
    if (index >= state->ai->mNumMaterials)
        return rad_fail(error, RAD_ERR_PARSE, "%s: a mesh names material %u of %u", state->path,
                        index, state->ai->mNumMaterials);
    if (state->material_map[index] == UINT32_MAX) {
        const struct aiMaterial *m = state->ai->mMaterials[index];
        struct aiString name;
        if (aiGetMaterialString(m, AI_MATKEY_NAME, &name) != aiReturn_SUCCESS)
            snprintf(name.data, sizeof(name.data), "material%u", index);
        rad_material material = {0};
        snprintf(material.name, sizeof(material.name), "%.*s", (int)sizeof(material.name) - 1,
                 name.data);
        material.albedo = material_color(m, AI_MATKEY_COLOR_DIFFUSE, (rad_rgb){0.5, 0.5, 0.5});
        material.emission = material_color(m, AI_MATKEY_COLOR_EMISSIVE, (rad_rgb){0, 0, 0});
        material.specular = material_color(m, AI_MATKEY_COLOR_SPECULAR, (rad_rgb){0, 0, 0});
        /* the array form: aiGetMaterialFloat is C99 inline and fails to link at -O0 */
        ai_real shininess = 0;
        unsigned one = 1;
        if (aiGetMaterialFloatArray(m, AI_MATKEY_SHININESS, &shininess, &one) == aiReturn_SUCCESS)
            material.shininess = shininess;
        state->material_map[index] = scene_builder_material(state->builder, &material);
        if (state->material_map[index] == UINT32_MAX)
            return rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory", state->path);
    }
    *out = state->material_map[index];
    return RAD_OK;
}

static rad_vec3 transform(const struct aiMatrix4x4 *m, struct aiVector3D v)
{
    return (rad_vec3){(double)m->a1 * v.x + (double)m->a2 * v.y + (double)m->a3 * v.z + m->a4,
                      (double)m->b1 * v.x + (double)m->b2 * v.y + (double)m->b3 * v.z + m->b4,
                      (double)m->c1 * v.x + (double)m->c2 * v.y + (double)m->c3 * v.z + m->c4};
}

static struct aiMatrix4x4 multiply(const struct aiMatrix4x4 *a, const struct aiMatrix4x4 *b)
{
    const float *x = &a->a1, *y = &b->a1;
    struct aiMatrix4x4 r;
    float *z = &r.a1;
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++)
            z[i * 4 + j] = x[i * 4 + 0] * y[0 * 4 + j] + x[i * 4 + 1] * y[1 * 4 + j] +
                           x[i * 4 + 2] * y[2 * 4 + j] + x[i * 4 + 3] * y[3 * 4 + j];
    return r;
}

static rad_status add_mesh(import_state *state, const struct aiMesh *mesh,
                           const struct aiNode *node, const struct aiMatrix4x4 *to_world,
                           rad_error *error)
{
    if (!(mesh->mPrimitiveTypes & aiPrimitiveType_TRIANGLE))
        return RAD_OK; /* points and lines carry no area */
    const char *name = mesh->mName.length ? mesh->mName.data
                       : node->mName.length ? node->mName.data
                                            : "unnamed";
    uint32_t surface = scene_builder_surface(state->builder, name);
    uint32_t material;
    if (surface == UINT32_MAX)
        return rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory", state->path);
    rad_status status = map_material(state, mesh->mMaterialIndex, &material, error);
    if (status != RAD_OK)
        return status;
    for (unsigned f = 0; f < mesh->mNumFaces; f++) {
        const struct aiFace *face = &mesh->mFaces[f];
        if (face->mNumIndices != 3)
            continue;
        rad_vec3 corner[3];
        for (int k = 0; k < 3; k++) {
            unsigned index = face->mIndices[k];
            if (index >= mesh->mNumVertices)
                return rad_fail(error, RAD_ERR_PARSE,
                                "%s: surface '%s': face %u uses vertex %u of %u", state->path,
                                name, f, index, mesh->mNumVertices);
            corner[k] = transform(to_world, mesh->mVertices[index]);
        }
        status = scene_builder_triangle(state->builder, surface, material, corner[0], corner[1],
                                        corner[2], error);
        if (status != RAD_OK)
            return status;
    }
    return RAD_OK;
}

static rad_status add_node(import_state *state, const struct aiNode *node,
                           const struct aiMatrix4x4 *parent, unsigned depth, rad_error *error)
{
    if (depth > 256)
        return rad_fail(error, RAD_ERR_PARSE, "%s: node tree deeper than 256", state->path);
    struct aiMatrix4x4 to_world = multiply(parent, &node->mTransformation);
    for (unsigned i = 0; i < node->mNumMeshes; i++) {
        unsigned index = node->mMeshes[i];
        if (index >= state->ai->mNumMeshes)
            return rad_fail(error, RAD_ERR_PARSE, "%s: a node names mesh %u of %u", state->path,
                            index, state->ai->mNumMeshes);
        rad_status status = add_mesh(state, state->ai->mMeshes[index], node, &to_world, error);
        if (status != RAD_OK)
            return status;
    }
    for (unsigned i = 0; i < node->mNumChildren; i++) {
        rad_status status = add_node(state, node->mChildren[i], &to_world, depth + 1, error);
        if (status != RAD_OK)
            return status;
    }
    return RAD_OK;
}

rad_status rad_scene_load(const char *path, const rad_load_options *options, rad_scene **out,
                          rad_error *error)
{
    *out = NULL;
    FILE *file = fopen(path, "rb");
    if (!file)
        return rad_fail(error, RAD_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    struct stat st;
    if (fstat(fileno(file), &st) != 0 || !S_ISREG(st.st_mode)) {
        fclose(file);
        return rad_fail(error, RAD_ERR_IO, "%s: cannot open: not a file", path);
    }
    rad_status status = RAD_OK;
    if (has_extension(path, ".obj"))
        status = check_obj(path, file, error);
    fclose(file);
    if (status != RAD_OK)
        return status;

    const struct aiScene *ai =
        aiImportFile(path, aiProcess_Triangulate | aiProcess_SortByPType);
    if (!ai)
        return rad_fail(error, RAD_ERR_PARSE, "%s: cannot read the scene: %s", path,
                        aiGetErrorString());

    scene_builder *builder = NULL;
    import_state state = {ai, NULL, NULL, path};
    status = scene_builder_create(path, options, &builder, error);
    if (status != RAD_OK)
        goto done;
    state.builder = builder;
    state.material_map = rad_alloc_array(ai->mNumMaterials, sizeof(*state.material_map));
    if (!state.material_map) {
        status = rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory", path);
        goto done;
    }
    for (unsigned m = 0; m < ai->mNumMaterials; m++)
        state.material_map[m] = UINT32_MAX;
    if (ai->mRootNode) {
        struct aiMatrix4x4 identity = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
        status = add_node(&state, ai->mRootNode, &identity, 0, error);
        if (status != RAD_OK)
            goto done;
    }
    status = scene_builder_finish(builder, out, error);
    builder = NULL;
done:
    scene_builder_destroy(builder);
    free(state.material_map);
    aiReleaseImport(ai);
    return status;
}
