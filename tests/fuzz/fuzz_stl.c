/*
 * fuzz_stl.c - libFuzzer target: the STL pre-check (check_stl in import_assimp.c: a binary file's size, an ASCII file's
 * closing endsolid),
 * then Assimp's reader and the scene builder, as rad_scene_load runs them. The pre-check
 * is file-local to import_assimp.c and reads a FILE, so the target goes through the
 * public rad_scene_load on the input written to a temporary input.stl.
 */
#include "fuzz_target.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *path = fuzz_write_file("input.stl", data, size);
    rad_scene *scene = NULL;
    rad_error error = {0};
    rad_status status = rad_scene_load(path, fuzz_quiet_options(), &scene, &error);
    fuzz_check_refusal(status, &error, path);
    if (status == RAD_OK)
        fuzz_check_scene(scene);
    rad_scene_destroy(scene);
    return 0;
}
