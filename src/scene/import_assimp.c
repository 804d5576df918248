/*
 * import_assimp.c - reading scene files through Assimp's C API.
 *
 * Assimp does the parsing. This file only (1) checks, for OBJ files (obj_check.c), what
 * Assimp passes over silently, gets wrong, or refuses without a line number: a material
 * library that is not there, face indices outside their v/vt/vn list (or beyond 64 bits),
 * v/vt/vn lines short of numbers or not finite; and hands Assimp a corrected copy of the
 * file where it would misread it (numbers written ".5", a comment after a face, several
 * libraries on one mtllib line, a library found by its base name beside the OBJ); every
 * failure of Assimp itself is put in our words after the file's name; for glTF files,
 * runs our own
 * reading (gltf_json.c) first; (2) walks Assimp's node tree, applying node transforms, and
 * hands triangles, materials and surface names to the scene builder. A surface is an
 * Assimp mesh name (OBJ `o`/`g`, glTF mesh, STL solid), else its node's name, else the
 * file's name without folder and extension; (3) maps materials onto METHOD.md's units:
 * Kd / glTF baseColorFactor = albedo, Ke / glTF emissiveFactor x emissiveStrength =
 * emitted radiance; a format's "no material" (STL, OBJ
 * faces before any usemtl or under a usemtl no library defines (a warning), glTF
 * primitives without one) gets RAD_DEFAULT_ALBEDO; albedo
 * and emission textures are decoded once each and triangles of textured materials keep
 * their texture coordinates; (4) takes the first glTF camera, and the up axis and unit
 * from the file's metadata; (5) adds the file's lights: glTF's KHR_lights_punctual as
 * gltf_json.c read them, other formats' (Collada, FBX) from Assimp's aiLight, each at the
 * node of its name, its values marked as in no known unit (rad_light.unit_unknown).
 * View3D input files are recognised here and handed to import_vs3.c, PLY files (by
 * extension or content) to import_ply.c: Assimp never reads PLY.
 */
#include <assimp/cimport.h>
#include <assimp/commonMetaData.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <ctype.h>
#include <errno.h>
#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

#include "core/alloc.h"
#include "core/error.h"
#include "core/vec3.h"
#include "scene/gltf_json.h"
#include "scene/obj_check.h"
#include "scene/import_ply.h"
#include "scene/scene_builder.h"
#include "scene/texture.h"

enum { TEXTURE_CACHE = 256 };

typedef struct texture_key {
    char key[1600];         /* the texture's file, or "*N" for an embedded one */
    uint32_t index;         /* 1 + index into the scene's textures */
} texture_key;

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

/* STL: an ASCII file ends with `endsolid` (Assimp 5.2 loads one cut short between facets
 * as if whole). Binary files (84 + 50 n bytes, whatever their first word) are Assimp's. */
static rad_status check_stl(const char *path, FILE *file, rad_error *error)
{
    unsigned char head[84];
    size_t got = fread(head, 1, sizeof(head), file);
    if (fseek(file, 0, SEEK_END) != 0)
        return RAD_OK;
    long size = ftell(file);
    bool text = true;
    for (size_t k = 0; k < got; k++)
        text = text && (isprint(head[k]) || isspace(head[k]) || head[k] >= 0x80); /* UTF-8 */
    if (got == sizeof(head)) {
        unsigned long count = (unsigned long)head[80] | (unsigned long)head[81] << 8 |
                              (unsigned long)head[82] << 16 | (unsigned long)head[83] << 24;
        if ((unsigned long long)size == 84 + 50ull * count)
            return RAD_OK;
        if (!text)
            return rad_fail(error, RAD_ERR_PARSE,
                            "%s: truncated or damaged: a binary STL of %lu triangles has %llu "
                            "bytes, this file %ld",
                            path, count, 84 + 50ull * count, size);
    }
    size_t start = 0;
    while (start < got && isspace(head[start]))
        start++;
    if (got - start < 5 || strncasecmp((const char *)head + start, "solid", 5) != 0)
        return RAD_OK; /* neither: Assimp says what it is not */
    char tail[256];
    long from = size > (long)sizeof(tail) - 1 ? size - (long)sizeof(tail) + 1 : 0;
    if (fseek(file, from, SEEK_SET) != 0)
        return RAD_OK;
    size_t n = fread(tail, 1, sizeof(tail) - 1, file);
    while (n > 0 && isspace((unsigned char)tail[n - 1]))
        n--;
    tail[n] = 0;
    char *last = tail + n; /* the start of the last line, ended by LF, CRLF or CR */
    while (last > tail && last[-1] != '\n' && last[-1] != '\r')
        last--;
    if (last == tail && from > 0)
        return RAD_OK; /* a last line longer than the tail (a long solid name): not checked */
    while (isspace((unsigned char)*last))
        last++;
    if (strncasecmp(last, "endsolid", 8) != 0)
        return rad_fail(error, RAD_ERR_PARSE,
                        "%s: truncated: an ASCII STL ends with 'endsolid', this one with '%.40s'",
                        path, last);
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
    const gltf_info *gltf;  /* our reading of a glTF file, else NULL */
    char stem[128];         /* the file's name without folder and extension */
    const rad_load_options *options;
    uint8_t *textured;      /* Assimp material index -> it has a texture (albedo or emission) */
    texture_key *cache;     /* textures already read (TEXTURE_CACHE at most) */
    unsigned cache_count;
    obj_names *obj_undefined; /* an OBJ's materials no library defines, else NULL */
} import_state;

static bool near_value(double a, double b)
{
    return fabs(a - b) <= 1e-6 * fmax(1, fabs(b));
}

/* Assimp's values of material m agree with the glTF file's material g. */
static bool same_gltf_material(const struct aiMaterial *m, const char *name,
                               const gltf_material *g)
{
    rad_rgb base = material_color(m, AI_MATKEY_COLOR_DIFFUSE, (rad_rgb){1, 1, 1});
    rad_rgb emissive = material_color(m, AI_MATKEY_COLOR_EMISSIVE, (rad_rgb){0, 0, 0});
    return strcmp(name, g->name) == 0 && near_value(base.r, g->base_color[0]) &&
           near_value(base.g, g->base_color[1]) && near_value(base.b, g->base_color[2]) &&
           near_value(emissive.r, g->emissive_factor[0]) &&
           near_value(emissive.g, g->emissive_factor[1]) &&
           near_value(emissive.b, g->emissive_factor[2]);
}

/* The glTF material behind Assimp material `index`, or NULL for Assimp's own default.
 * Assimp 5.2 numbers glTF materials by first reference in its walk of the scene (see
 * gltf_json.h), which gltf_json.c replays; the values Assimp read must then agree with
 * that JSON material (name, base colour, emissive factor). If they do not (an Assimp
 * whose walk differs), the material is looked up by those values among all of the file's
 * materials; if that leaves several with different emissive strengths, a warning says
 * which strength was taken. */
static const gltf_material *gltf_material_of(const import_state *state, unsigned index,
                                             const struct aiMaterial *m, const char *name)
{
    const gltf_info *g = state->gltf;
    const gltf_material *walked = index < g->assimp_count ? &g->materials[g->assimp_order[index]]
                                                          : NULL;
    if (walked && same_gltf_material(m, name, walked))
        return walked;
    const gltf_material *found = NULL;
    bool ambiguous = false;
    for (uint32_t k = 0; k < g->material_count; k++)
        if (same_gltf_material(m, name, &g->materials[k])) {
            ambiguous |= found && found->emissive_strength != g->materials[k].emissive_strength;
            if (!found)
                found = &g->materials[k];
        }
    if (!found && walked)
        rad_warn(state->options ? state->options->log : NULL,
                 state->options ? state->options->log_user : NULL,
                 "%s: material '%s': not found in the glTF JSON; emissive strength 1 assumed",
                 state->path, name);
    if (ambiguous)
        rad_warn(state->options ? state->options->log : NULL,
                 state->options ? state->options->log_user : NULL,
                 "%s: material '%s': several glTF materials match with different emissive "
                 "strengths; %g taken",
                 state->path, name, found->emissive_strength);
    return found;
}

/* Texture 0 of Assimp type `type` of material m, for `role`: a file beside the scene, or
 * an image a glb embeds ("*N"). Returns 1 + its index into the scene's textures, or 0 when
 * there is none. A texture that is missing or cannot be decoded is a warning: the value is
 * then the material's colour. Images already read are shared (one decode per file, the
 * same sRGB decoding for every role). */
static uint32_t take_texture(import_state *state, const struct aiMaterial *m,
                             enum aiTextureType type, const rad_material *material,
                             const char *role, rad_error *error)
{
    struct aiString texture;
    unsigned uv_set = 0;
    if (aiGetMaterialTexture(m, type, 0, &texture, NULL, &uv_set, NULL, NULL, NULL, NULL) !=
            aiReturn_SUCCESS ||
        texture.length == 0)
        return 0;
    rad_log_fn log = state->options ? state->options->log : NULL;
    void *user = state->options ? state->options->log_user : NULL;
    if (uv_set != 0)
        rad_warn(log, user, "%s: material '%s': %s texture '%s' uses texture coordinates %u; "
                 "only set 0 is read, so it is looked up there",
                 state->path, material->name, role, texture.data, uv_set);
    char key[sizeof(state->cache[0].key)];
    if (texture.data[0] == '*' || texture.data[0] == '/')
        snprintf(key, sizeof(key), "%s", texture.data);
    else {
        char folder[512];
        folder_of(state->path, folder, sizeof(folder));
        snprintf(key, sizeof(key), "%s%s", folder, texture.data);
    }
    for (unsigned k = 0; k < state->cache_count; k++)
        if (strcmp(state->cache[k].key, key) == 0)
            return state->cache[k].index;
    rad_texture decoded;
    rad_error why = {0};
    rad_status status = RAD_ERR_IO;
    if (texture.data[0] == '*') {
        char name[600];
        unsigned long n = strtoul(texture.data + 1, NULL, 10);
        const struct aiTexture *embedded = n < state->ai->mNumTextures ? state->ai->mTextures[n]
                                                                       : NULL;
        snprintf(name, sizeof(name), "%.500s#%lu", state->path, n);
        if (!embedded)
            snprintf(why.message, sizeof(why.message), "embedded texture %lu is not in the file",
                     n);
        else if (embedded->mHeight != 0)
            snprintf(why.message, sizeof(why.message),
                     "embedded texture %lu is raw texels (not supported)", n);
        else
            status = texture_decode(name, (const unsigned char *)embedded->pcData,
                                    embedded->mWidth, &decoded, &why);
    } else {
        struct stat st;
        if (stat(key, &st) != 0 || !S_ISREG(st.st_mode)) {
            rad_warn(log, user, "%s: material '%s': texture '%s' not found; its %s is the "
                     "material's colour",
                     state->path, material->name, texture.data, role);
            return 0;
        }
        status = texture_load_file(key, &decoded, &why);
    }
    if (status == RAD_ERR_NOMEM) {
        *error = why;
        return 0;
    }
    if (status != RAD_OK) {
        rad_warn(log, user, "%s: material '%s': texture '%s': %s; its %s is the material's "
                 "colour",
                 state->path, material->name, texture.data, why.message, role);
        return 0;
    }
    uint32_t index = scene_builder_texture(state->builder, &decoded);
    if (!state->cache)
        state->cache = rad_alloc_array(TEXTURE_CACHE, sizeof(*state->cache));
    if (!index || !state->cache) {
        rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory", state->path);
        return 0;
    }
    if (state->cache_count < TEXTURE_CACHE) {
        snprintf(state->cache[state->cache_count].key, sizeof(state->cache[0].key), "%s", key);
        state->cache[state->cache_count++].index = index;
    }
    return index;
}

/* The material's textures: albedo (MTL map_Kd, glTF baseColorTexture: Assimp's diffuse
 * texture 0) and emission (MTL map_Ke, glTF emissiveTexture: Assimp's emissive texture 0,
 * verified with Assimp 5.2 for both formats). An emission texture multiplies the emission
 * factor, so with a zero factor (MTL Ke missing, glTF emissiveFactor missing) it shows
 * nothing: a warning says so. */
static rad_status take_textures(import_state *state, const struct aiMaterial *m,
                                rad_material *material, rad_error *error)
{
    rad_error lack = {0}; /* RAD_ERR_NOMEM, else every problem is a warning */
    material->albedo_texture =
        take_texture(state, m, aiTextureType_DIFFUSE, material, "albedo", &lack);
    if (lack.status == RAD_OK)
        material->emission_texture =
            take_texture(state, m, aiTextureType_EMISSIVE, material, "emission", &lack);
    if (lack.status != RAD_OK) {
        if (error)
            *error = lack;
        return lack.status;
    }
    const rad_rgb *e = &material->emission;
    if (material->emission_texture && !(e->r > 0 || e->g > 0 || e->b > 0))
        rad_warn(state->options ? state->options->log : NULL,
                 state->options ? state->options->log_user : NULL,
                 "%s: material '%s': an emission texture but an emission factor of 0 (MTL Ke, "
                 "glTF emissiveFactor): it emits nothing",
                 state->path, material->name);
    return RAD_OK;
}

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
            name.data[0] = 0;
        const gltf_material *gltf = state->gltf ? gltf_material_of(state, index, m, name.data)
                                                : NULL;
        /* Assimp's stand-in when the file has no material: "DefaultMaterial" (OBJ, STL,
         * Collada; 3DS adds "_N"), the unnamed one it appends after glTF's own */
        bool gltf_default = state->gltf && !gltf && name.data[0] == 0 &&
                            index + 1 == state->ai->mNumMaterials;
        bool is_default = strncmp(name.data, AI_DEFAULT_MATERIAL_NAME,
                                  strlen(AI_DEFAULT_MATERIAL_NAME)) == 0 ||
                          gltf_default;
        /* an OBJ's usemtl that no library defines: no material, under its own name */
        bool undefined = state->obj_undefined && obj_names_has(state->obj_undefined, name.data);
        rad_material material = {0};
        if (is_default || undefined) {
            snprintf(material.name, sizeof(material.name), "%.*s",
                     (int)sizeof(material.name) - 1, undefined ? name.data : "default");
            is_default = true;
            material.albedo = (rad_rgb){RAD_DEFAULT_ALBEDO, RAD_DEFAULT_ALBEDO, RAD_DEFAULT_ALBEDO};
        } else {
            if (name.data[0])
                snprintf(material.name, sizeof(material.name), "%.*s",
                         (int)sizeof(material.name) - 1, name.data);
            else
                snprintf(material.name, sizeof(material.name), "material%u", index);
            material.albedo = material_color(m, AI_MATKEY_COLOR_DIFFUSE,
                                             (rad_rgb){RAD_DEFAULT_ALBEDO, RAD_DEFAULT_ALBEDO,
                                                       RAD_DEFAULT_ALBEDO});
            material.emission = material_color(m, AI_MATKEY_COLOR_EMISSIVE, (rad_rgb){0, 0, 0});
            material.specular = material_color(m, AI_MATKEY_COLOR_SPECULAR, (rad_rgb){0, 0, 0});
            if (gltf) {
                /* glTF: emitted radiance = emissiveFactor x KHR_materials_emissive_strength;
                 * Assimp's specular is its own guess from metallic-roughness: none */
                material.emission.r *= gltf->emissive_strength;
                material.emission.g *= gltf->emissive_strength;
                material.emission.b *= gltf->emissive_strength;
                material.specular = (rad_rgb){0, 0, 0};
            } else {
                /* the array form: aiGetMaterialFloat is C99 inline and fails to link at -O0 */
                ai_real shininess = 0;
                unsigned one = 1;
                if (aiGetMaterialFloatArray(m, AI_MATKEY_SHININESS, &shininess, &one) ==
                    aiReturn_SUCCESS)
                    material.shininess = shininess;
                /* files in the wild put a light's power in the ambient colour (MTL Ka),
                 * which no reflectance can exceed 1: say so, and how to make it emit */
                rad_rgb ambient = material_color(m, AI_MATKEY_COLOR_AMBIENT, (rad_rgb){0, 0, 0});
                if (fmax(ambient.r, fmax(ambient.g, ambient.b)) > 1 &&
                    fmax(material.emission.r, fmax(material.emission.g, material.emission.b)) <= 0)
                    rad_warn(state->options ? state->options->log : NULL,
                             state->options ? state->options->log_user : NULL,
                             "%s: material '%s' has an ambient colour Ka (%g, %g, %g) above 1 "
                             "but no Ke: it does not emit (--emit %s=R,G,B makes it a light)",
                             state->path, material.name, ambient.r, ambient.g, ambient.b,
                             material.name);
            }
            /* Ks without Kd: radiosity and the path tracer see a black surface */
            if (fmax(material.albedo.r, fmax(material.albedo.g, material.albedo.b)) <= 0 &&
                fmax(material.specular.r, fmax(material.specular.g, material.specular.b)) > 0)
                rad_warn(state->options ? state->options->log : NULL,
                         state->options ? state->options->log_user : NULL,
                         "%s: material '%s' has a specular colour Ks but no diffuse Kd: "
                         "radiosity treats it as black (diffuse albedo 0); only the Whitted "
                         "tracer (raytrace) and render --specular show its specular part",
                         state->path, material.name);
        }
        if (!is_default) {
            rad_status status = take_textures(state, m, &material, error);
            if (status != RAD_OK)
                return status;
        }
        state->textured[index] = material.albedo_texture != 0 || material.emission_texture != 0;
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
                                            : state->stem;
    uint32_t surface = scene_builder_surface(state->builder, name);
    uint32_t material;
    if (surface == UINT32_MAX)
        return rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory", state->path);
    rad_status status = map_material(state, mesh->mMaterialIndex, &material, error);
    if (status != RAD_OK)
        return status;
    /* glTF doubleSided (Assimp's TWOSIDED; only glTF's: Collada exporters set theirs on
     * everything): every surface using the material radiates on both sides */
    int two_sided = 0;
    unsigned one = 1;
    if (state->gltf &&
        aiGetMaterialIntegerArray(state->ai->mMaterials[mesh->mMaterialIndex], AI_MATKEY_TWOSIDED,
                                  &two_sided, &one) == aiReturn_SUCCESS &&
        two_sided)
        scene_builder_set_surface_flags(state->builder, surface, RAD_SURFACE_TWO_SIDED);
    const struct aiVector3D *uvs =
        state->textured[mesh->mMaterialIndex] ? mesh->mTextureCoords[0] : NULL;
    for (unsigned f = 0; f < mesh->mNumFaces; f++) {
        const struct aiFace *face = &mesh->mFaces[f];
        if (face->mNumIndices != 3)
            continue;
        rad_vec3 corner[3];
        float uv[3][2];
        for (int k = 0; k < 3; k++) {
            unsigned index = face->mIndices[k];
            if (index >= mesh->mNumVertices)
                return rad_fail(error, RAD_ERR_PARSE,
                                "%s: surface '%s': face %u uses vertex %u of %u", state->path,
                                name, f, index, mesh->mNumVertices);
            corner[k] = transform(to_world, mesh->mVertices[index]);
            if (uvs) {
                uv[k][0] = uvs[index].x;
                uv[k][1] = uvs[index].y;
            }
        }
        status = uvs ? scene_builder_triangle_uv(state->builder, surface, material, corner,
                                                 (const float(*)[2])uv, error)
                     : scene_builder_triangle(state->builder, surface, material, corner[0],
                                              corner[1], corner[2], error);
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

static bool find_node(const struct aiNode *node, const char *name, const struct aiMatrix4x4 *parent,
                      unsigned depth, struct aiMatrix4x4 *to_world)
{
    struct aiMatrix4x4 here = multiply(parent, &node->mTransformation);
    if (strcmp(node->mName.data, name) == 0) {
        *to_world = here;
        return true;
    }
    for (unsigned i = 0; depth < 256 && i < node->mNumChildren; i++)
        if (find_node(node->mChildren[i], name, &here, depth + 1, to_world))
            return true;
    return false;
}

/* The first camera of a glTF file, placed by its node. Assimp 5.2's glTF importer copies
 * the node's translation into mPosition as well, so the camera sits at its node's origin;
 * it reports mHorizontalFOV = yfov x aspectRatio (yfov alone without an aspect ratio),
 * from which the vertical field of view is recovered exactly. Other importers' cameras
 * follow other conventions in Assimp 5.2 and are not used. */
static void take_gltf_camera(const struct aiScene *ai, scene_builder *builder)
{
    if (ai->mNumCameras == 0 || !ai->mRootNode)
        return;
    const struct aiCamera *c = ai->mCameras[0];
    struct aiMatrix4x4 identity = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}, to_world;
    if (!find_node(ai->mRootNode, c->mName.data, &identity, 0, &to_world))
        return;
    struct aiVector3D origin = {0, 0, 0};
    struct aiVector3D ahead = {c->mLookAt.x, c->mLookAt.y, c->mLookAt.z};
    struct aiVector3D above = {c->mUp.x, c->mUp.y, c->mUp.z};
    rad_camera camera;
    camera.eye = transform(&to_world, origin);
    camera.target = transform(&to_world, ahead);
    camera.up = v3_sub(transform(&to_world, above), camera.eye);
    double vertical = c->mAspect > 0 ? c->mHorizontalFOV / c->mAspect : c->mHorizontalFOV;
    camera.fov_degrees = vertical * 180.0 / RAD_PI;
    if (!(camera.fov_degrees > 0 && camera.fov_degrees < 180) || !v3_is_finite(camera.eye) ||
        !v3_is_finite(camera.target) || !(v3_length(camera.up) > 0) ||
        !(v3_length(v3_sub(camera.target, camera.eye)) > 0))
        return;
    scene_builder_set_camera(builder, &camera);
}

/* Adds one light read from the file; a light the scene refuses is the file's fault. */
static rad_status add_file_light(const import_state *state, rad_scene *scene,
                                 const rad_light *light, rad_error *error)
{
    rad_error why = {0};
    rad_status status = rad_scene_add_light(scene, light, &why);
    if (status == RAD_ERR_NOMEM)
        return rad_fail(error, status, "%s: out of memory for its lights", state->path);
    if (status != RAD_OK)
        return rad_fail(error, RAD_ERR_PARSE, "%s: %s", state->path, why.message);
    return RAD_OK;
}

/* glTF: the KHR_lights_punctual lights gltf_json.c read and placed (Assimp 5.2's aiLight
 * for glTF keeps the cone half-angles where aiLight means full angles). */
static rad_status add_gltf_lights(const import_state *state, rad_scene *scene, rad_error *error)
{
    const gltf_info *g = state->gltf;
    if (g->ranged_light_count)
        rad_warn(state->options ? state->options->log : NULL,
                 state->options ? state->options->log_user : NULL,
                 "%s: light '%s'%s gives a range, which is ignored: lights fall off by the "
                 "inverse-square law without a cut-off",
                 state->path, g->ranged_light_name,
                 g->ranged_light_count > 1 ? " (and others)" : "");
    for (uint32_t l = 0; l < g->light_count; l++) {
        rad_status status = add_file_light(state, scene, &g->lights[l], error);
        if (status != RAD_OK)
            return status;
    }
    return RAD_OK;
}

/* Assimp's scene came from an FBX file (its importer names itself in the metadata). */
static bool from_fbx(const struct aiScene *ai)
{
    const struct aiMetadata *meta = ai->mMetaData;
    for (unsigned k = 0; meta && k < meta->mNumProperties; k++)
        if (strcmp(meta->mKeys[k].data, AI_METADATA_SOURCE_FORMAT) == 0 &&
            meta->mValues[k].mType == AI_AISTRING && meta->mValues[k].mData)
            return strstr(((const struct aiString *)meta->mValues[k].mData)->data, "FBX") != NULL;
    return false;
}

/* Every node of the tree in depth-first pre-order, with its transform to the world. */
typedef struct placed_node {
    const struct aiNode *node;
    struct aiMatrix4x4 to_world;
} placed_node;

static size_t count_nodes(const struct aiNode *node, unsigned depth)
{
    size_t count = 1;
    for (unsigned i = 0; depth < 256 && i < node->mNumChildren; i++)
        count += count_nodes(node->mChildren[i], depth + 1);
    return count;
}

static void place_nodes(const struct aiNode *node, const struct aiMatrix4x4 *parent,
                        unsigned depth, placed_node *nodes, size_t *count)
{
    placed_node *here = &nodes[(*count)++];
    here->node = node;
    here->to_world = multiply(parent, &node->mTransformation);
    for (unsigned i = 0; depth < 256 && i < node->mNumChildren; i++)
        place_nodes(node->mChildren[i], &here->to_world, depth + 1, nodes, count);
}

/* The node holding light k. An aiLight names its node, and names need not be unique (an
 * FBX light instanced under two nodes, 3ds Max's duplicate names): Assimp 5.2's Collada
 * and FBX importers make lights in a depth-first pre-order walk of the nodes, so the j-th
 * light named N belongs to the j-th node named N that holds no mesh. When the counts
 * disagree (a mesh or an empty node of the same name besides), the only node of that
 * name, else the first, is taken, and *ambiguous says so. NULL: no node of that name. */
static const placed_node *light_node(const struct aiScene *ai, unsigned k,
                                     const placed_node *nodes, size_t node_count,
                                     bool *ambiguous)
{
    const char *name = ai->mLights[k]->mName.data;
    unsigned before = 0, lights = 0;
    for (unsigned l = 0; l < ai->mNumLights; l++)
        if (strcmp(ai->mLights[l]->mName.data, name) == 0) {
            before += l < k;
            lights++;
        }
    const placed_node *first = NULL, *chosen = NULL;
    unsigned named = 0, holders = 0;
    for (size_t n = 0; n < node_count; n++) {
        if (strcmp(nodes[n].node->mName.data, name) != 0)
            continue;
        if (!first)
            first = &nodes[n];
        named++;
        if (nodes[n].node->mNumMeshes == 0 && holders++ == before)
            chosen = &nodes[n];
    }
    *ambiguous = false;
    if (holders == lights && chosen)
        return chosen;
    *ambiguous = named > 1;
    return first;
}

/* Other formats: Assimp's lights (Collada, FBX, ...), each at its node (light_node), its
 * mPosition and mDirection in that node's space. Assimp's cone angles are full angles,
 * halved here. What Assimp 5.2 makes of each format, verified by tests/test_file_lights.c:
 * - Collada: the colour as given; the inner cone is falloff_angle, the outer one
 *   falloff_angle plus penumbra_angle (or Assimp's guess from falloff_exponent).
 * - FBX: colour = Color x Intensity / 100 (FBX's Intensity is a percentage); a light
 *   shines along its node's -Y (mDirection (0,-1,0)); InnerAngle and OuterAngle are the
 *   full cone angles in degrees, which Assimp turns into radians (the convention of the
 *   FBX SDK, Maya and Blender's exporter); LightType 3 and 4 (area, volume) come as
 *   undefined lights; DecayType becomes attenuation factors (none: constant = DecayStart;
 *   linear: linear = 2 / DecayStart; quadratic, Assimp's default: quadratic = 2 /
 *   DecayStart^2; cubic: linear 1, quadratic 1), which are ignored: every light falls off
 *   by the inverse-square law, and a warning names an FBX light whose decay is another.
 *   Lengths stay in the file's unit (UnitScaleFactor, in take_frame).
 * Neither format's light values are photometric: the colour is taken as candela or lux as
 * given and the light is marked unit_unknown. */
static rad_status add_assimp_lights(const import_state *state, rad_scene *scene,
                                    rad_error *error)
{
    rad_log_fn log = state->options ? state->options->log : NULL;
    void *user = state->options ? state->options->log_user : NULL;
    const struct aiScene *ai = state->ai;
    if (ai->mNumLights == 0)
        return RAD_OK;
    bool fbx = from_fbx(ai);
    size_t node_count = 0;
    placed_node *nodes = NULL;
    if (ai->mRootNode) {
        nodes = rad_alloc_array(count_nodes(ai->mRootNode, 0), sizeof(*nodes));
        if (!nodes)
            return rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory for its lights",
                            state->path);
        struct aiMatrix4x4 identity = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
        place_nodes(ai->mRootNode, &identity, 0, nodes, &node_count);
    }
    unsigned taken = 0;
    rad_status status = RAD_OK;
    for (unsigned k = 0; k < ai->mNumLights && status == RAD_OK; k++) {
        const struct aiLight *a = ai->mLights[k];
        rad_light light = {0};
        snprintf(light.name, sizeof(light.name), "%.*s", (int)sizeof(light.name) - 1,
                 a->mName.data);
        switch (a->mType) {
        case aiLightSource_POINT: light.type = RAD_LIGHT_POINT; break;
        case aiLightSource_SPOT: light.type = RAD_LIGHT_SPOT; break;
        case aiLightSource_DIRECTIONAL: light.type = RAD_LIGHT_DIRECTIONAL; break;
        default:
            rad_warn(log, user, "%s: light '%s' is %s, which is not read", state->path,
                     light.name,
                     a->mType == aiLightSource_AREA      ? "an area light"
                     : a->mType == aiLightSource_AMBIENT ? "an ambient light"
                     : fbx ? "an area or volume light (Assimp reads neither's shape)"
                           : "of a type Assimp does not know");
            continue;
        }
        bool ambiguous;
        const placed_node *node = light_node(ai, k, nodes, node_count, &ambiguous);
        struct aiMatrix4x4 to_world = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
        if (node)
            to_world = node->to_world;
        else
            rad_warn(log, user, "%s: light '%s': no node of that name; its position and "
                     "direction are taken as given",
                     state->path, light.name);
        if (ambiguous)
            rad_warn(log, user, "%s: light '%s': several nodes have that name; it is placed at "
                     "the first",
                     state->path, light.name);
        struct aiVector3D ahead = {a->mPosition.x + a->mDirection.x,
                                   a->mPosition.y + a->mDirection.y,
                                   a->mPosition.z + a->mDirection.z};
        light.position = transform(&to_world, a->mPosition);
        light.direction = v3_sub(transform(&to_world, ahead), light.position);
        light.intensity = (rad_rgb){a->mColorDiffuse.r, a->mColorDiffuse.g, a->mColorDiffuse.b};
        light.unit_unknown = true;
        if (light.type == RAD_LIGHT_SPOT) {
            light.inner_degrees = a->mAngleInnerCone / 2 * 180 / RAD_PI;
            light.outer_degrees = a->mAngleOuterCone / 2 * 180 / RAD_PI;
            if (light.outer_degrees > 90) {
                rad_warn(log, user, "%s: spot light '%s': its cone (half-angle %.4g degrees) "
                         "is wider than a hemisphere; 90 degrees taken",
                         state->path, light.name, light.outer_degrees);
                light.outer_degrees = 90;
            }
            if (light.inner_degrees > light.outer_degrees)
                light.inner_degrees = light.outer_degrees;
        }
        bool inverse_square = a->mAttenuationConstant == 0 && a->mAttenuationLinear == 0 &&
                              a->mAttenuationQuadratic > 0;
        if (fbx && light.type != RAD_LIGHT_DIRECTIONAL && !inverse_square)
            rad_warn(log, user, "%s: light '%s': its FBX decay is %s; it falls off by the "
                     "inverse-square law instead",
                     state->path, light.name,
                     a->mAttenuationQuadratic > 0 ? "cubic"
                     : a->mAttenuationLinear > 0  ? "linear"
                                                  : "none (constant light at any distance)");
        status = add_file_light(state, scene, &light, error);
        taken += status == RAD_OK;
    }
    free(nodes);
    if (status == RAD_OK && taken)
        rad_warn(log, user, "%s: %u light%s in no known unit: %s is taken as candela "
                 "(point, spot) or lux (sun), so results are relative, not photometric "
                 "(--point, --spot and --sun give photometric lights)",
                 state->path, taken, taken > 1 ? "s" : "",
                 fbx ? "FBX's Color x Intensity / 100" : "each colour");
    return status;
}

/* The shortest decimal that reads back as the float f: the value the file wrote, where
 * Assimp kept it in single precision (FBX's UnitScaleFactor 2.54 is 2.5399999618f). */
static double decimal_of_float(float f)
{
    char text[32];
    for (int digits = 1; digits <= 9; digits++) {
        snprintf(text, sizeof(text), "%.*g", digits, (double)f);
        if (strtof(text, NULL) == f)
            return strtod(text, NULL);
    }
    return f;
}

/* A numeric metadata value. */
static bool metadata_number(const struct aiScene *ai, const char *key, double *out)
{
    const struct aiMetadata *meta = ai->mMetaData;
    for (unsigned k = 0; meta && k < meta->mNumProperties; k++) {
        if (strcmp(meta->mKeys[k].data, key) != 0 || !meta->mValues[k].mData)
            continue;
        const void *data = meta->mValues[k].mData;
        switch (meta->mValues[k].mType) {
        case AI_INT32: *out = *(const int32_t *)data; return true;
        case AI_UINT64: *out = (double)*(const uint64_t *)data; return true;
        case AI_FLOAT: *out = decimal_of_float(*(const float *)data); return true;
        case AI_DOUBLE: *out = *(const double *)data; return true;
        default: return false;
        }
    }
    return false;
}

/* Up axis and unit: glTF is y-up metres by definition; Collada becomes y-up metres in
 * Assimp, which scales by its <unit meter> and turns its <up_axis> in the root node; FBX
 * says UpAxis (0,1,2), UpAxisSign and UnitScaleFactor (centimetres per unit) in Assimp's
 * metadata. */
static void take_frame(const struct aiScene *ai, bool metres_y_up, scene_builder *builder)
{
    rad_vec3 up = {0, 1, 0};
    double unit = metres_y_up ? 1 : 0, axis, sign = 1, centimetres;
    if (metadata_number(ai, "UpAxis", &axis) && axis >= 0 && axis <= 2) {
        metadata_number(ai, "UpAxisSign", &sign);
        up = (rad_vec3){0, 0, 0};
        (&up.x)[(int)axis] = sign < 0 ? -1 : 1;
    }
    if (metadata_number(ai, "UnitScaleFactor", &centimetres) && centimetres > 0)
        unit = centimetres / 100;
    scene_builder_set_frame(builder, up, unit);
}

/* Assimp's failure to read `path`, in our words where we know what it means (the checks
 * above catch what they can first, with a line), with Assimp's own on one line after. */
static rad_status assimp_failure(const char *path, const char *assimp, rad_error *error)
{
    static const struct {
        const char *assimp, *meaning;
    } known[] = {
        {"too small", "the file is empty or too short to hold a scene"},
        {"vertex index out of range", "a face refers to a vertex the file does not define"},
        {"normal index out of range", "a face refers to a normal the file does not define"},
        {"color index out of range", "a face refers to a vertex colour the file does not define"},
        {"Invalid number of components", "a v, vt or vn line has the wrong number of numbers"},
        {"Division by zero", "a vertex has weight w = 0"},
        {"Invalid face index", "a face corner is not a whole-number index"},
        {"Not supported token in face", "a face corner is not v, v/vt, v//vn or v/vt/vn"},
        {"as a real number", "a number cannot be read"},
        {"No suitable reader found", "not a scene format Assimp reads"},
        {"Unable to open file", "cannot be opened"},
    };
    const char *meaning = "a construct Assimp cannot read";
    for (size_t k = 0; k < sizeof(known) / sizeof(known[0]); k++)
        if (strstr(assimp, known[k].assimp)) {
            meaning = known[k].meaning;
            break;
        }
    rad_status status = rad_fail(error, RAD_ERR_PARSE, "%s: cannot read the scene: %s (Assimp: %s)",
                                 path, meaning, assimp);
    for (char *text = error ? error->message : NULL; text && *text; text++)
        if (*text == '\n' || *text == '\r')
            *text = ' ';
    return status;
}

/* View3D content: the first data line (not blank, not a `!` or `/` comment) starts with
 * T, C or F and a blank, and some line of the first 64 KiB is `F 3` alone (a comment may
 * follow). OBJ files start with comments (#), mtllib, o, g or v lines, and their face
 * lines have three vertices or more. */
static bool looks_like_vs3(FILE *file)
{
    char line[1024];
    bool first = true, geometry = false;
    size_t read = 0;
    while (read < 65536 && fgets(line, sizeof(line), file)) {
        read += strlen(line);
        char *p = line;
        while (*p == ' ' || *p == '\t')
            p++;
        if (!*p || *p == '\n' || *p == '\r' || *p == '!' || *p == '/')
            continue;
        if (first) {
            if (!strchr("TtCcFf", *p) || !(p[1] == ' ' || p[1] == '\t'))
                return false;
            first = false;
        }
        if ((p[0] == 'F' || p[0] == 'f') && (p[1] == ' ' || p[1] == '\t')) {
            char *q = p + 1;
            while (*q == ' ' || *q == '\t')
                q++;
            if (q[0] == '3') {
                q++;
                while (*q == ' ' || *q == '\t' || *q == '\r' || *q == '\n')
                    q++;
                geometry |= !*q || *q == '!' || *q == '/';
            }
        }
    }
    return geometry;
}

bool rad_scene_is_vs3(const char *path)
{
    FILE *file = fopen(path, "rb");
    if (!file)
        return false;
    bool vs3 = has_extension(path, ".vs3") || looks_like_vs3(file);
    fclose(file);
    return vs3;
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
    if (has_extension(path, ".vs3") || looks_like_vs3(file)) {
        fclose(file);
        return rad_scene_load_vs3(path, options, out, NULL, error);
    }
    rewind(file);
    if (has_extension(path, ".ply") || ply_stream_is_ply(file)) { /* Assimp never reads PLY */
        fclose(file);
        return ply_scene_load(path, options, out, error);
    }
    rewind(file);
    rad_status status = RAD_OK;
    import_state state = {NULL, NULL, NULL, path, NULL, "", options, NULL, NULL, 0, NULL};
    gltf_info gltf = {0};
    bool is_gltf = has_extension(path, ".gltf") || has_extension(path, ".glb");
    obj_check obj = {0};
    if (has_extension(path, ".obj"))
        status = obj_check_read(path, options, file, &obj, error);
    else if (has_extension(path, ".stl"))
        status = check_stl(path, file, error);
    fclose(file);
    if (status == RAD_OK && is_gltf) {
        status = gltf_info_read(path, &gltf, error);
        state.gltf = &gltf;
    }
    if (status == RAD_OK && obj.copy_differs && obj.copy_length > UINT_MAX)
        status = rad_fail(error, RAD_ERR_UNSUPPORTED,
                          "%s: an OBJ of more than 4 GiB with .5 numbers, a comment after a "
                          "face or libraries to find is not supported",
                          path);
    if (status != RAD_OK) {
        obj_check_free(&obj);
        return status;
    }
    const char *base = strrchr(path, '/') ? strrchr(path, '/') + 1 : path;
    snprintf(state.stem, sizeof(state.stem), "%s", base);
    char *dot = strrchr(state.stem, '.');
    if (dot && dot != state.stem)
        *dot = 0;

    /* an OBJ that must be told differently: Assimp reads the checked copy, whose
     * mtllib lines name their files from the working folder */
    unsigned flags = aiProcess_Triangulate | aiProcess_SortByPType;
    const struct aiScene *ai =
        obj.copy_differs
            ? aiImportFileFromMemory(obj.copy, (unsigned)obj.copy_length, flags, "obj")
            : aiImportFile(path, flags);
    free(obj.copy);
    obj.copy = NULL;
    if (!ai) {
        status = assimp_failure(path, aiGetErrorString(), error);
        gltf_info_free(&gltf);
        obj_check_free(&obj);
        return status;
    }
    state.ai = ai;
    state.obj_undefined = obj.materials_undefined.length ? &obj.materials_undefined : NULL;

    scene_builder *builder = NULL;
    status = scene_builder_create(path, options, &builder, error);
    if (status != RAD_OK)
        goto done;
    state.builder = builder;
    state.material_map = rad_alloc_array(ai->mNumMaterials, sizeof(*state.material_map));
    state.textured = rad_alloc_array(ai->mNumMaterials, sizeof(*state.textured));
    if (!state.material_map || !state.textured) {
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
    if (is_gltf)
        take_gltf_camera(ai, builder);
    take_frame(ai, is_gltf || has_extension(path, ".dae"), builder);
    status = scene_builder_finish(builder, out, error);
    builder = NULL;
    if (status == RAD_OK) {
        status = is_gltf ? add_gltf_lights(&state, *out, error)
                         : add_assimp_lights(&state, *out, error);
        if (status != RAD_OK) {
            rad_scene_destroy(*out);
            *out = NULL;
        }
    }
done:
    scene_builder_destroy(builder);
    free(state.material_map);
    free(state.textured);
    free(state.cache);
    gltf_info_free(&gltf);
    obj_check_free(&obj);
    aiReleaseImport(ai);
    return status;
}
