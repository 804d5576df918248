/*
 * test_furnace.c - the furnace (VALIDATION.md section 3): a closed cube whose every
 * surface has Ke = 1 and Kd = 0.5 shows radiance 1 / (1 - 0.5) = 2 in every pixel, for
 * every solver, rendered to .pfm from inside. It checks closure of the form factors, the
 * solvers, the reconstruction and the renderer together.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "testlib.h"


static void check_solver(const char *solver)
{
    char command[512];
    snprintf(command, sizeof(command),
             "render furnace.obj -o furnace-%s.pfm --solver %s --tolerance 1e-6 "
             "--eye 0.5,0.5,0.05 --target 0.5,0.5,1 --up 0,1,0 --fov 100 --size 48x40 "
             "--patch-size 0.125",
             solver, solver);
    int code = test_run_tool(command);
    CHECK(code == 0);
    if (code != 0) {
        fprintf(stderr, "%s\n", test_read_text(test_path("stderr.txt")));
        return;
    }
    char name[64];
    snprintf(name, sizeof(name), "furnace-%s.pfm", solver);
    rad_image *image = NULL;
    rad_error error;
    CHECK(rad_image_read(test_path(name), &image, &error) == RAD_OK);
    if (!image)
        return;
    CHECK(image->width == 48 && image->height == 40);
    double lo = INFINITY, hi = -INFINITY;
    size_t n = (size_t)image->width * image->height * 3;
    int outside = 0;
    for (size_t k = 0; k < n; k++) {
        lo = fmin(lo, image->rgb[k]);
        hi = fmax(hi, image->rgb[k]);
        outside += fabs(image->rgb[k] - 2.0) > 0.01;
    }
    printf("%s: pixels in [%.6f, %.6f]\n", solver, lo, hi);
    CHECK(outside == 0);
    CHECK_NEAR(lo, 2.0, 0.005);
    CHECK_NEAR(hi, 2.0, 0.005);
    rad_image_destroy(image);
}

int main(void)
{
    test_write_furnace("furnace.obj");
    check_solver("gather");
    check_solver("gauss-seidel");
    check_solver("shoot");
    check_solver("direct");
    return test_finish("test_furnace");
}
