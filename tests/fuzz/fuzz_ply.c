/*
 * fuzz_ply.c - libFuzzer target: the project's PLY reader (import_ply.c, with the header
 * parser ply_header.c) on the input in memory (fmemopen), the whole load up to a finished
 * scene; rad_scene_load hands every PLY file to this reader, so nothing else reads one.
 */
#include <stdio.h>

#include "fuzz_target.h"
#include "scene/import_ply.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size == 0)
        return 0; /* fmemopen needs a byte; the empty file is in the wild corpus */
    FILE *file = fmemopen((void *)(uintptr_t)data, size, "rb");
    if (!file)
        return 0;
    rad_error error = {0};
    rad_scene *scene = NULL;
    rad_status status = ply_scene_read("input.ply", file, fuzz_quiet_options(), &scene, &error);
    fclose(file);
    fuzz_check_refusal(status, &error, "input.ply");
    if (status == RAD_OK)
        fuzz_check_scene(scene);
    rad_scene_destroy(scene);
    return 0;
}
