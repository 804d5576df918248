/*
 * fuzz_ply.c - libFuzzer target: the PLY pre-check (ply_check.c) on the input in memory
 * (fmemopen); an input it accepts then goes through the whole load (rad_scene_load, which
 * hands it to Assimp), since the check exists to keep Assimp from reading past a file's
 * data: what it lets through must load or be refused cleanly.
 */
#include <stdio.h>

#include "fuzz_target.h"
#include "scene/ply_check.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size == 0)
        return 0; /* fmemopen needs a byte; the empty file is in the wild corpus */
    FILE *file = fmemopen((void *)(uintptr_t)data, size, "rb");
    if (!file)
        return 0;
    rad_error error = {0};
    rad_status status = ply_check("input.ply", file, &error);
    fclose(file);
    fuzz_check_refusal(status, &error, "input.ply");
    if (status != RAD_OK)
        return 0;
    const char *path = fuzz_write_file("input.ply", data, size);
    rad_scene *scene = NULL;
    status = rad_scene_load(path, fuzz_quiet_options(), &scene, &error);
    fuzz_check_refusal(status, &error, path);
    if (status == RAD_OK)
        fuzz_check_scene(scene);
    rad_scene_destroy(scene);
    return 0;
}
