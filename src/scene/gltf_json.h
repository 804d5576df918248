/*
 * gltf_json.h - what our own reading of a glTF 2.0 file (.gltf JSON or .glb container)
 * adds to Assimp's: the checks Assimp makes with unclear messages (a truncated .glb, a
 * buffer file that is not there), the material data Assimp 5.2 drops
 * (KHR_materials_emissive_strength), tied to Assimp's material numbering, and the
 * KHR_lights_punctual lights placed by their nodes.
 */
#ifndef RAD_SCENE_GLTF_JSON_H
#define RAD_SCENE_GLTF_JSON_H

#include "radiosity.h"

/* One entry of the file's "materials" array. */
typedef struct gltf_material {
    char name[128];
    double base_color[3];        /* pbrMetallicRoughness.baseColorFactor, (1,1,1) if absent */
    double emissive_factor[3];   /* emissiveFactor, (0,0,0) if absent */
    double emissive_strength;    /* KHR_materials_emissive_strength, 1 if absent */
} gltf_material;

typedef struct gltf_info {
    gltf_material *materials; /* the JSON array, in file order */
    uint32_t material_count;
    /* Assimp 5.2 numbers glTF materials in the order its importer first meets them while
     * it walks the default scene (node, its children first, then its mesh's primitives),
     * then the skins' joints and the animations' targets; unreferenced materials are
     * dropped and a default material is appended. assimp_order[k] is the JSON index of
     * Assimp material k by that walk, for k < assimp_count. */
    uint32_t *assimp_order;
    uint32_t assimp_count;
    /* KHR_lights_punctual: one light per node of the default scene that holds one (a light
     * several nodes share comes once per node), in the order of a depth-first walk from
     * the scene's roots, placed at the node's world transform and shining along its -Z
     * axis; intensity = color x intensity (cd for point and spot, lux for directional);
     * spot cone half-angles in degrees. */
    rad_light *lights;
    uint32_t light_count;
    uint32_t ranged_light_count;     /* lights whose `range` is given (and ignored) */
    char ranged_light_name[128];     /* the first of them */
} gltf_info;

/* Reads and checks path (.gltf or .glb). Errors name the file. */
rad_status gltf_info_read(const char *path, gltf_info *out, rad_error *error);

void gltf_info_free(gltf_info *info);

#endif
