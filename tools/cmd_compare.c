/*
 * cmd_compare.c - `radiosity compare A B [-o DIFF]`: how far image A is from the reference
 * B (RMSE, mean relative error, block statistics), and a false-colour difference picture.
 *
 * A measuring tool: any difference is a result, not a failure, so it exits 0 whenever both
 * images could be read and compared. The numbers come from rad_image_compare.
 */
#include <math.h>
#include <stdlib.h>

#include "cli.h"

static const char usage[] =
    "usage: radiosity compare A B [-o DIFF.png|.hdr|.pfm|.exr] [options]\n"
    "\n"
    "Compares image A with the reference image B (each .pfm, Radiance .hdr or OpenEXR\n"
    ".exr; the same size) and prints, one 'name: value' per line:\n"
    "  size                     WIDTHxHEIGHT\n"
    "  rmse                     root mean square of A - B over pixels and channels\n"
    "  mean_relative_error      mean of |A - B|_1 / |B|_1 over the pixels where B is not\n"
    "                           black (|v|_1 = |r| + |g| + |b|)\n"
    "  block_relative_rmse      RMS over blocks of |Y_A - Y_B| / Y_B, block mean luminances\n"
    "                           (Y_B floored at 1e-3 of its image mean)\n"
    "  pixel_relative_rmse      sqrt(mean (Y_A - Y_B)^2) / mean Y_B, leaving out lights seen\n"
    "                           directly (Y_B over 20 x its median) and 2 pixels around them\n"
    "  mean_a, mean_b           mean radiance per channel: R G B\n"
    "  worst_block              X,Y (top-left pixel) and relative difference of the block\n"
    "                           whose mean differs most: |mean_A - mean_B|_1 / |mean_B|_1\n"
    "                           ('inf' where B's block is black and A's is not)\n"
    "  blocks_within_tolerance  fraction of blocks within the tolerance (count of total)\n"
    "Blocks are N x N pixels from the top-left corner; partial blocks at the right and\n"
    "bottom edges are left out. The exit code is 0 whatever the difference.\n"
    "\n"
    "  -o, --output FILE        write the false-colour difference (.png, .hdr, .pfm or\n"
    "                           .exr): per pixel |A - B|_1 / |B|_1 from blue (0) through\n"
    "                           cyan, green (50 %) and yellow to red (100 % or more)\n"
    "  --block N                block side in pixels (default " CLI_STR(RAD_DEFAULT_BLOCK_SIZE) ")\n"
    "  --block-tolerance X      relative difference a block may have (default "
    CLI_STR(RAD_DEFAULT_BLOCK_TOLERANCE) ")\n"
    "  --stats FILE.json        write the same numbers as JSON\n"
    "The numbers on standard output are the whole report: compare prints no summary line\n"
    "on stderr (--quiet is accepted and changes nothing).\n"
    "  -h, --help               this text\n";

enum { OPT_BLOCK = OPT_OWN, OPT_BLOCK_TOLERANCE, OPT_COUNT };

static const cli_option options[OPT_COUNT] = {
    CLI_BASE_OPTIONS,
    [OPT_BLOCK] = {"block", 0, true},
    [OPT_BLOCK_TOLERANCE] = {"block-tolerance", 0, true},
};

/* The largest --block: far beyond any useful block, small enough that block^2 fits. */
#define MAX_BLOCK 65535ul

/* The false colours are exact at exposure 0 (2^0 = 1): the ramp's corners are 0 and 1. */
static const rad_image_write_options false_colour_write = {.fixed_exposure = true,
                                                           .exposure = 0};

static bool parse_compare_options(const cli_args *args, rad_compare_options *compare)
{
    if (!cli_parse_count("block", args->value[OPT_BLOCK], 1, MAX_BLOCK, &compare->block_size))
        return false;
    if (args->value[OPT_BLOCK_TOLERANCE]) {
        /* positive: 0 would mean the library's default */
        if (!cli_parse_positive("block-tolerance", args->value[OPT_BLOCK_TOLERANCE],
                                &compare->block_tolerance))
            return false;
    }
    return true;
}

static void print_report(const rad_image *a, const rad_image_difference *d, uint32_t block,
                         unsigned long within)
{
    printf("size: %ux%u\n", (unsigned)a->width, (unsigned)a->height);
    printf("rmse: %.6g\n", d->rmse);
    printf("mean_relative_error: %.6g\n", d->mean_relative_error);
    printf("block_relative_rmse: %.6g\n", d->block_relative_rmse);
    printf("pixel_relative_rmse: %.6g (%u pixels of lights left out)\n", d->pixel_relative_rmse,
           (unsigned)d->pixels_left_out);
    printf("mean_a: %.6g %.6g %.6g\n", d->mean_a.r, d->mean_a.g, d->mean_a.b);
    printf("mean_b: %.6g %.6g %.6g\n", d->mean_b.r, d->mean_b.g, d->mean_b.b);
    printf("worst_block: %u,%u %.6g\n", (unsigned)d->worst_block_x, (unsigned)d->worst_block_y,
           d->worst_block_error);
    printf("blocks_within_tolerance: %.6g (%lu of %u blocks of %ux%u)\n",
           d->blocks_within_tolerance, within, (unsigned)d->block_count, (unsigned)block,
           (unsigned)block);
}

int command_compare(int argc, char **argv)
{
    cli_args args;
    cli_shared shared;
    int exit_code;
    if (!cli_begin("compare", usage, argc, argv, options, OPT_COUNT, &args, &shared, &exit_code))
        return exit_code;
    if (args.positional_count != 2) {
        cli_error("compare: give two images, A and the reference B (see 'radiosity compare "
                  "--help')");
        return EXIT_USAGE;
    }
    rad_compare_options compare = {0};
    if (!parse_compare_options(&args, &compare))
        return EXIT_USAGE;
    const char *path_a = args.positional[0], *path_b = args.positional[1];
    const char *output = shared.output, *stats_path = shared.stats_path;
    if (output && !cli_image_output_ok(output))
        return EXIT_USAGE;
    if (!cli_outputs_writable((const char *[]){output, stats_path}, 2))
        return EXIT_ERROR;

    rad_error error = {0};
    rad_image *a = NULL, *b = NULL, *false_colour = NULL;
    rad_image_difference difference;
    rad_status status = rad_image_read(path_a, &a, &error);
    if (status == RAD_OK)
        status = rad_image_read(path_b, &b, &error);
    if (status == RAD_OK && output && a->width == b->width && a->height == b->height)
        status = rad_image_create(a->width, a->height, &false_colour, &error);
    if (status != RAD_OK)
        goto fail;
    status = rad_image_compare(a, b, &compare, &difference, false_colour, &error);
    if (status != RAD_OK) {
        /* The library knows the images as a and b; name the files. */
        cli_error("%s (a) vs %s (b): %s", path_a, path_b, error.message);
        exit_code = EXIT_ERROR;
        goto done;
    }

    uint32_t block = compare.block_size ? compare.block_size : RAD_DEFAULT_BLOCK_SIZE;
    unsigned long within =
        (unsigned long)difference.blocks_within;
    print_report(a, &difference, block, within);
    if (fflush(stdout) != 0) {
        cli_error("standard output: write failed");
        exit_code = EXIT_ERROR;
        goto done;
    }

    if (output) {
        status = rad_image_write(false_colour, output, &false_colour_write, &error);
        if (status != RAD_OK)
            goto fail;
    }
    cli_stats stats;
    stats_begin(&stats);
    stats_string(&stats, "a", path_a);
    stats_string(&stats, "b", path_b);
    stats_integer(&stats, "width", a->width);
    stats_integer(&stats, "height", a->height);
    stats_number(&stats, "rmse", difference.rmse);
    stats_number(&stats, "mean_relative_error", difference.mean_relative_error);
    stats_number(&stats, "mean_a_r", difference.mean_a.r);
    stats_number(&stats, "mean_a_g", difference.mean_a.g);
    stats_number(&stats, "mean_a_b", difference.mean_a.b);
    stats_number(&stats, "mean_b_r", difference.mean_b.r);
    stats_number(&stats, "mean_b_g", difference.mean_b.g);
    stats_number(&stats, "mean_b_b", difference.mean_b.b);
    stats_number(&stats, "worst_block_error", difference.worst_block_error); /* inf: null */
    stats_integer(&stats, "worst_block_x", difference.worst_block_x);
    stats_integer(&stats, "worst_block_y", difference.worst_block_y);
    stats_integer(&stats, "block_size", block);
    stats_integer(&stats, "block_count", difference.block_count);
    stats_integer(&stats, "blocks_within", within);
    stats_number(&stats, "blocks_within_tolerance", difference.blocks_within_tolerance);
    stats_number(&stats, "block_tolerance", compare.block_tolerance > 0
                                                ? compare.block_tolerance
                                                : RAD_DEFAULT_BLOCK_TOLERANCE);
    exit_code = cli_finish(&stats, stats_path, NULL); /* the report on stdout is the summary */
    goto done;
fail:
    exit_code = cli_failed(&error);
done:
    rad_image_destroy(false_colour);
    rad_image_destroy(b);
    rad_image_destroy(a);
    return exit_code;
}
