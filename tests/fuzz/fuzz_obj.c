/*
 * fuzz_obj.c - libFuzzer target: the OBJ pre-check (check_obj in import_assimp.c: face indices, finite
 * coordinates, material libraries),
 * then Assimp's reader and the scene builder, as rad_scene_load runs them. The pre-check
 * is file-local to import_assimp.c and reads a FILE, so the target goes through the
 * public rad_scene_load on the input written to a temporary input.obj.
 */
#include "fuzz_target.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *path = fuzz_write_file("input.obj", data, size);
    rad_scene *scene = NULL;
    rad_error error = {0};
    rad_status status = rad_scene_load(path, fuzz_quiet_options(), &scene, &error);
    fuzz_check_refusal(status, &error, path);
    if (status == RAD_OK)
        fuzz_check_scene(scene);
    rad_scene_destroy(scene);
    return 0;
}
