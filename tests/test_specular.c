/*
 * test_specular.c - `render --specular`, the two-pass method: the radiosity solution for
 * diffuse light plus mirror reflections traced through the radiosity-lit scene.
 *
 * A mirror (Kd 0, Ks 0.8) faces the camera; behind the camera an emitter (Kd 0, so its
 * radiosity is exactly its emission) faces the mirror. Every pixel then shows exactly
 * Ks x Le through the mirror, and 0 without --specular (the mirror has no diffuse part).
 */
#include <math.h>
#include <stdio.h>

#include "testlib.h"

static const char *scene_obj =
    "mtllib mirror.mtl\n"
    "o mirror\nusemtl glass\n"
    "v -1 -1 0\nv -1 1 0\nv 1 1 0\nv 1 -1 0\nf 1 2 3 4\n"
    "o lamp\nusemtl lamp\n"
    "v -3 -3 -2\nv 3 -3 -2\nv 3 3 -2\nv -3 3 -2\nf 5 6 7 8\n";

static const char *scene_mtl = "newmtl glass\nKd 0 0 0\nKs 0.8 0.8 0.8\n"
                               "newmtl lamp\nKd 0 0 0\nKe 2 1 0.5\n";

static rad_image *render(const char *name, const char *extra)
{
    char command[512];
    snprintf(command, sizeof(command),
             "render mirror.obj -o %s --eye 0,0,-1 --target 0,0,0 --up 0,1,0 --fov 60 "
             "--size 16x16 --patch-size 0.5 %s",
             name, extra);
    int code = test_run_tool(command);
    CHECK(code == 0);
    if (code != 0) {
        fprintf(stderr, "%s\n", test_read_text(test_path("stderr.txt")));
        return NULL;
    }
    rad_image *image = NULL;
    rad_error error;
    CHECK(rad_image_read(test_path(name), &image, &error) == RAD_OK);
    return image;
}

int main(void)
{
    test_write_file("mirror.obj", scene_obj);
    test_write_file("mirror.mtl", scene_mtl);
    const double expected[3] = {0.8 * 2, 0.8 * 1, 0.8 * 0.5};

    rad_image *mirror = render("specular.pfm", "--specular");
    rad_image *plain = render("plain.pfm", "");
    if (mirror && plain) {
        double worst = 0, brightest_plain = 0;
        for (size_t p = 0; p < 16 * 16; p++)
            for (int c = 0; c < 3; c++) {
                worst = fmax(worst, fabs(mirror->rgb[p * 3 + c] - expected[c]) / expected[c]);
                brightest_plain = fmax(brightest_plain, plain->rgb[p * 3 + c]);
            }
        printf("through the mirror: worst relative error %.3g; without --specular: %.3g\n",
               worst, brightest_plain);
        CHECK(worst < 1e-5);
        CHECK(brightest_plain == 0);
    }
    rad_image_destroy(mirror);
    rad_image_destroy(plain);

    /* depth: a depth of 1 still reaches the lamp (one reflection) */
    rad_image *shallow = render("shallow.pfm", "--specular --max-depth 1");
    if (shallow)
        CHECK_NEAR(shallow->rgb[(8 * 16 + 8) * 3], expected[0], 1e-5);
    rad_image_destroy(shallow);
    CHECK(test_run_tool("render mirror.obj -o x.pfm --specular --max-depth 0") == 2);

    /* the same scene 30000 units from the origin: float hit points are coarser there, and
     * mirror rays must still leave the mirror without hitting it again */
    test_write_file("far.obj",
                    "mtllib mirror.mtl\n"
                    "o mirror\nusemtl glass\n"
                    "v 29999 29999 30000\nv 29999 30001 30000\nv 30001 30001 30000\n"
                    "v 30001 29999 30000\nf 1 2 3 4\n"
                    "o lamp\nusemtl lamp\n"
                    "v 29997 29997 29998\nv 30003 29997 29998\nv 30003 30003 29998\n"
                    "v 29997 30003 29998\nf 5 6 7 8\n");
    CHECK(test_run_tool("render far.obj -o far.pfm --eye 30000,30000,29999 "
                        "--target 30000,30000,30000 --up 0,1,0 --fov 60 --size 32x32 "
                        "--patch-size 0.5 --specular") == 0);
    rad_image *far = NULL;
    rad_error error;
    CHECK(rad_image_read(test_path("far.pfm"), &far, &error) == RAD_OK);
    if (far) {
        int wrong = 0;
        for (size_t p = 0; p < 32 * 32; p++)
            wrong += fabs(far->rgb[p * 3] - expected[0]) > 1e-3 * expected[0];
        printf("far from the origin: %d of 1024 pixels wrong\n", wrong);
        CHECK(wrong == 0);
    }
    rad_image_destroy(far);
    return test_finish("test_specular");
}
