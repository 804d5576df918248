/*
 * patch_size.c - benchmark helper: finds the patch size that meshes the built-in Cornell
 * box into about N patches, by bisection on rad_mesh_build (the count depends on how the
 * mesher splits edges and merges regions, so it is measured, not derived from the area).
 *
 * usage: patch_size N [N...]
 * prints, per N:  patch_size_for_patches target=N patch_size=MM patches=COUNT
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "radiosity.h"

static void die(const char *what)
{
    fprintf(stderr, "patch_size: %s\n", what);
    exit(1);
}

static uint32_t patch_count(const rad_scene *scene, double size)
{
    rad_error error = {0};
    rad_mesh *mesh = NULL;
    if (rad_mesh_build(scene, size, &mesh, &error) != RAD_OK)
        die(error.message);
    uint32_t count = mesh->patch_count;
    rad_mesh_destroy(mesh);
    return count;
}

/* x rounded to 4 significant digits, so the size prints exactly as it was measured. */
static double round4(double x)
{
    char text[32];
    snprintf(text, sizeof(text), "%.4g", x);
    return strtod(text, NULL);
}

int main(int argc, char **argv)
{
    if (argc < 2 || strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0) {
        puts("usage: patch_size N [N...]");
        return argc < 2 ? 1 : 0;
    }
    rad_error error = {0};
    rad_scene *scene = NULL;
    if (rad_scene_cornell_box(&scene, &error) != RAD_OK)
        die(error.message);
    for (int a = 1; a < argc; a++) {
        char *end = NULL;
        unsigned long target = strtoul(argv[a], &end, 10);
        if (*end || target < 1 || target > 1000000)
            die("N must be a whole number from 1 to 1000000");
        /* The count falls as the size grows: bisect between a quarter and 4 times the
         * size that area / size^2 = N would give, keeping the closest count seen. */
        double guess = rad_mesh_default_patch_size(scene, (uint32_t)target);
        double lo = guess / 4, hi = guess * 4; /* lo: more patches, hi: fewer */
        double best_size = round4(guess);
        uint32_t best_count = patch_count(scene, best_size);
        for (int step = 0; step < 40 && hi / lo > 1.0001; step++) {
            double size = round4(sqrt(lo * hi));
            uint32_t count = patch_count(scene, size);
            if (labs((long)count - (long)target) < labs((long)best_count - (long)target)) {
                best_size = size;
                best_count = count;
            }
            if (count == target)
                break;
            if (count > target)
                lo = size;
            else
                hi = size;
        }
        printf("patch_size_for_patches target=%lu patch_size=%g patches=%u\n", target,
               best_size, best_count);
    }
    rad_scene_destroy(scene);
    return 0;
}
