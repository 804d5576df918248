/*
 * fuzz_mtl.c - libFuzzer target: the input is a material library, input.mtl, beside a
 * fixed OBJ that names it and uses the materials "white", "light" and "tex" (the seed
 * corpus defines them), textured and not; the OBJ goes through rad_scene_load (the OBJ
 * pre-check, Assimp's MTL reader, our mapping of Kd/Ke/Ka/Ks/Ns and map_Kd/map_Ke).
 */
#include <string.h>

#include "fuzz_target.h"

static const char scene_obj[] =
    "mtllib input.mtl\n"
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 1 1 1\n"
    "vt 0 0\nvt 1 0\nvt 0 1\n"
    "o floor\nusemtl white\nf 1/1 2/2 3/3\n"
    "o lamp\nusemtl light\nf 1 2 4\n"
    "o picture\nusemtl tex\nf 2/1 5/2 4/3\n"
    "o other\nusemtl undefined\nf 3 5 4\n";

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fuzz_write_file("input.mtl", data, size);
    const char *path =
        fuzz_write_file("scene.obj", (const uint8_t *)scene_obj, strlen(scene_obj));
    rad_scene *scene = NULL;
    rad_error error = {0};
    rad_status status = rad_scene_load(path, fuzz_quiet_options(), &scene, &error);
    fuzz_check_refusal(status, &error, path);
    if (status == RAD_OK)
        fuzz_check_scene(scene);
    rad_scene_destroy(scene);
    return 0;
}
