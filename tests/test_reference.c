/*
 * test_reference.c - radiosity against the path tracer, the Monte-Carlo reference
 * (VALIDATION.md section 3, "Against Monte Carlo"): the built-in Cornell box at its
 * official camera, rendered by `render` and by `pathtrace` at 512 samples per pixel, then
 * compared by `compare`: the mean radiance per channel within 3 %, and at least 90 % of
 * the 8x8 blocks within 10 % (the expected differences: discretisation near corners and
 * shadow edges).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "testlib.h"

static rad_image *read_image(const char *name)
{
    rad_image *image = NULL;
    rad_error error;
    if (rad_image_read(test_path(name), &image, &error) != RAD_OK)
        test_fail(__FILE__, __LINE__, "%s", error.message);
    return image;
}

int main(void)
{
    CHECK(test_run_tool("render -o radiosity.pfm --size 128x128") == 0);
    CHECK(test_run_tool("pathtrace -o reference.pfm --size 128x128 --spp 512 --seed 11") == 0);
    rad_image *radiosity = read_image("radiosity.pfm"), *reference = read_image("reference.pfm");
    if (!radiosity || !reference)
        return test_finish("test_reference");

    rad_image_difference d;
    rad_error error;
    CHECK(rad_image_compare(radiosity, reference, NULL, &d, NULL, &error) == RAD_OK);
    printf("mean radiosity %.5f %.5f %.5f, path traced %.5f %.5f %.5f\n", d.mean_a.r,
           d.mean_a.g, d.mean_a.b, d.mean_b.r, d.mean_b.g, d.mean_b.b);
    printf("rmse %.5f, blocks within 10%%: %u of %u, worst block %.3f at (%u, %u)\n", d.rmse,
           d.blocks_within, d.block_count, d.worst_block_error, d.worst_block_x,
           d.worst_block_y);
    CHECK_NEAR(d.mean_a.r, d.mean_b.r, 0.03);
    CHECK_NEAR(d.mean_a.g, d.mean_b.g, 0.03);
    CHECK_NEAR(d.mean_a.b, d.mean_b.b, 0.03);
    CHECK(d.block_count == 256);
    CHECK(d.blocks_within_tolerance >= 0.90);

    /* and the CLI says the same */
    CHECK(test_run_tool("compare radiosity.pfm reference.pfm -o difference.png") == 0);
    CHECK(strstr(test_read_text(test_path("stdout.txt")), "blocks_within_tolerance:") != NULL);
    CHECK(test_file_exists(test_path("difference.png")));
    rad_image_destroy(radiosity);
    rad_image_destroy(reference);
    return test_finish("test_reference");
}
