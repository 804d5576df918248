/*
 * fuzz_vs3.c - libFuzzer target: View3D input files, the whole of import_vs3.c (parse,
 * resolve, build). The reader takes a path, so the input is written to a temporary file
 * first (fuzz_target.h).
 */
#include "fuzz_target.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *path = fuzz_write_file("input.vs3", data, size);
    rad_scene *scene = NULL;
    rad_vs3_control control;
    rad_error error = {0};
    rad_status status = rad_scene_load_vs3(path, fuzz_quiet_options(), &scene, &control, &error);
    fuzz_check_refusal(status, &error, path);
    if (status == RAD_OK)
        fuzz_check_scene(scene);
    rad_scene_destroy(scene);
    return 0;
}
