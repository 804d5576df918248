/*
 * test_edges.c - antialiasing of high-contrast edges in `render`: pixels whose first
 * samples disagree get 64 more. An emitter (Kd 0, Ke 1) seen against black through a
 * pinhole whose image maps the emitter's edge to 30 % across pixel column 8: every pixel
 * of that column covers 70 % of emitter, so its radiance is 0.7 (closed form from the
 * camera model in the test). With 2 x 2 samples alone a pixel could be off by 0.2.
 */
#include <math.h>
#include <stdio.h>

#include "testlib.h"

int main(void)
{
    /* camera at (0,0,-1) looking +z, fov 90, 16 x 16: pixel column 8 spans image x from 0 to
     * 0.125 (tan 45 = 1), and image x grows towards world -X. The emitter covers world
     * X <= -0.0375, i.e. image x >= 0.0375 = 30 % into the column. */
    test_write_file("edge.mtl", "newmtl lamp\nKd 0 0 0\nKe 1 1 1\n");
    test_write_file("edge.obj", "mtllib edge.mtl\nusemtl lamp\no lamp\n"
                                "v -3 -3 0\nv -3 3 0\nv -0.0375 3 0\nv -0.0375 -3 0\n"
                                "f 1 2 3 4\n");
    int code = test_run_tool("render edge.obj -o edge.pfm --eye 0,0,-1 --target 0,0,0 "
                             "--up 0,1,0 --fov 90 --size 16x16 --spp 4 --patch-size 1");
    CHECK(code == 0);
    rad_image *image = NULL;
    rad_error error;
    CHECK(rad_image_read(test_path("edge.pfm"), &image, &error) == RAD_OK);
    if (!image)
        return test_finish("test_edges");
    double worst = 0, mean = 0;
    for (uint32_t y = 0; y < 16; y++) {
        double value = image->rgb[((size_t)y * 16 + 8) * 3];
        worst = fmax(worst, fabs(value - 0.7));
        mean += value / 16;
        /* the columns either side are wholly black or wholly lit */
        CHECK(image->rgb[((size_t)y * 16 + 7) * 3] == 0);
        CHECK_NEAR(image->rgb[((size_t)y * 16 + 9) * 3], 1.0, 1e-6);
    }
    printf("edge column: mean %.4f, worst pixel off by %.4f (coverage 0.7)\n", mean, worst);
    CHECK_NEAR(mean, 0.7, 0.02);
    CHECK(worst < 0.1);
    rad_image_destroy(image);
    return test_finish("test_edges");
}
