/*
 * fuzz_gltf_json.c - libFuzzer target: our own pass over a glTF file (gltf_json.c: the
 * .glb container, the JSON's buffers, views, accessors, materials and the node walk that
 * numbers materials as Assimp does). An input starting with the .glb magic "glTF" is
 * written as input.glb, any other as input.gltf (the reader takes a path). Assimp is not
 * called.
 */
#include <stdlib.h>
#include <string.h>

#include "fuzz_target.h"
#include "scene/gltf_json.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    bool glb = size >= 4 && memcmp(data, "glTF", 4) == 0;
    const char *path = fuzz_write_file(glb ? "input.glb" : "input.gltf", data, size);
    gltf_info info = {0};
    rad_error error = {0};
    rad_status status = gltf_info_read(path, &info, &error);
    fuzz_check_refusal(status, &error, path);
    for (uint32_t k = 0; status == RAD_OK && k < info.assimp_count; k++)
        if (info.assimp_order[k] >= info.material_count)
            abort(); /* Assimp's material k mapped past the JSON's materials */
    gltf_info_free(&info);
    return 0;
}
