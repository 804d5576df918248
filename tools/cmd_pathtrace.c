/*
 * cmd_pathtrace.c - `radiosity pathtrace [SCENE] -o OUT [options]`: the Monte-Carlo
 * reference image of a scene (or the built-in Cornell box) by unbiased path tracing.
 * A thin client of rad_pathtrace; nothing here computes light. Under mpirun the ranks
 * share the tiles (the library does) and rank 0 alone writes.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "cli.h"
#include "cli_ranks.h"

static const char usage[] =
    "usage: radiosity pathtrace [SCENE] -o OUT [options]\n"
    "\n"
    "Renders SCENE (an OBJ+MTL or any file Assimp reads; none = the built-in Cornell box\n"
    "with its official camera) by unbiased path tracing of its Lambertian surfaces (Kd\n"
    "albedo, Ke emitted radiance; one-sided unless two-sided: --two-sided, glTF\n"
    "doubleSided): cosine-weighted bounces, next-event\n"
    "estimation on the emitters with multiple importance sampling, Russian roulette. The\n"
    "image is the reference a radiosity image is checked against; the same seed gives the\n"
    "same image for any thread count. OUT's extension picks the format: .png (exposure,\n"
    "tone map, sRGB 8-bit), .hdr (Radiance RGBE), .pfm (portable float map) or .exr\n"
    "(OpenEXR, half float); .hdr, .pfm and .exr hold linear radiance.\n"
    "\n"
    CLI_CAMERA_HELP
    CLI_IMAGE_FILE_HELP
    "Sampling:\n"
    "  --spp N              paths per pixel, stratified over the pixel, box filter\n"
    "                       (default " CLI_STR(RAD_DEFAULT_PATHTRACE_SPP) "); the noise falls as 1/sqrt(N)\n"
    "  --max-depth N        most bounces per path (default 0: no limit, Russian roulette\n"
    "                       ends paths without bias)\n"
    "  --standard-error FILE  also write each pixel's standard error of the mean, per\n"
    "                       channel (.hdr, .pfm or .exr)\n"
    CLI_TWO_SIDED_HELP
    "  --max-memory SIZE    bytes the whole run may hold (K, M, G): images (refused at\n"
    "                       once when they cannot fit), scene, BVH, buffers; anything\n"
    "                       else past it ends the run with an error\n"
    CLI_BASE_HELP("rays, times, mean radiance and peak memory");

enum { OPT_MAX_DEPTH = OPT_OWN, OPT_STANDARD_ERROR, OPT_TWO_SIDED, OPT_COUNT };

static const cli_option options[OPT_COUNT] = {
    CLI_BASE_OPTIONS,
    CLI_VIEW_OPTIONS,
    CLI_SCENE_OPTIONS,
    [OPT_MAX_MEMORY] = {"max-memory", 0, true},
    [OPT_MAX_DEPTH] = {"max-depth", 0, true},
    [OPT_STANDARD_ERROR] = {"standard-error", 0, true},
    [OPT_TWO_SIDED] = {"two-sided", 0, true},
};

typedef struct pathtrace_settings {
    const char *scene_path, *error_path;
    cli_shared shared;
    cli_view view;
    rad_pathtrace_options trace;
    cli_two_sided two_sided;
    uint64_t max_memory; /* --max-memory, 0 = none */
} pathtrace_settings;

static bool parse_settings(int argc, char **argv, pathtrace_settings *s, int *exit_code)
{
    cli_args args;
    memset(s, 0, sizeof(*s));
    if (!cli_parse_image_command("pathtrace", usage, argc, argv, options, OPT_COUNT, &args,
                                 &s->shared, &s->view, &s->scene_path, exit_code))
        return false;
    s->error_path = args.value[OPT_STANDARD_ERROR];
    cli_parse_two_sided(&args, OPT_TWO_SIDED, &s->two_sided);
    if (s->error_path && s->view.samples_per_pixel == 1) {
        cli_error("--standard-error: needs at least 2 samples per pixel (--spp)");
        return false;
    }
    if (s->error_path) {
        const char *dot = strrchr(s->error_path, '.');
        if (!cli_image_output_ok(s->error_path))
            return false;
        if (dot && strcasecmp(dot, ".png") == 0) {
            cli_error("--standard-error: %s: use .hdr, .pfm or .exr (a standard error is "
                      "not a picture)",
                      s->error_path);
            return false;
        }
    }
    if (!cli_parse_count("max-depth", args.value[OPT_MAX_DEPTH], 0, 1u << 20,
                         &s->trace.max_depth))
        return false;
    if (args.value[OPT_MAX_MEMORY] &&
        !cli_parse_bytes("max-memory", args.value[OPT_MAX_MEMORY], &s->max_memory))
        return false;
    s->trace.samples_per_pixel = s->view.samples_per_pixel; /* 0 = the library's default */
    CLI_SET_RUN_OPTIONS(s->trace, s->shared);
    *exit_code = EXIT_OK;
    return true;
}

/* Mean radiance of the image per channel. */
static rad_rgb image_mean(const rad_image *image)
{
    double sum[3] = {0, 0, 0};
    size_t pixels = (size_t)image->width * image->height;
    for (size_t p = 0; p < pixels; p++)
        for (int c = 0; c < 3; c++)
            sum[c] += image->rgb[p * 3 + c];
    return (rad_rgb){sum[0] / pixels, sum[1] / pixels, sum[2] / pixels};
}

/* Root mean square of the per-pixel standard errors, over pixels and channels. */
static double rms_standard_error(const rad_image *se)
{
    double sum = 0;
    size_t n = (size_t)se->width * se->height * 3;
    for (size_t k = 0; k < n; k++)
        sum += (double)se->rgb[k] * se->rgb[k];
    return sqrt(sum / n);
}

int command_pathtrace(int argc, char **argv)
{
    pathtrace_settings s;
    int exit_code;
    if (!parse_settings(argc, argv, &s, &exit_code))
        return exit_code;
    const char *output = s.shared.output;
    if (!cli_outputs_writable((const char *[]){output, s.shared.stats_path, s.error_path}, 3))
        return EXIT_ERROR;
    /* the image, and the standard error's when it is written or reported */
    int images = s.error_path || s.shared.stats_path ? 2 : 1;
    char image_name[80];
    snprintf(image_name, sizeof(image_name), "the %u x %u image%s", s.view.width,
             s.view.height, images == 2 ? " with its standard error" : "");
    cli_memory_budget(s.max_memory);
    if (!cli_memory_take(cli_image_bytes(&s.view, output, images), image_name))
        return EXIT_ERROR;

    rad_error error = {0};
    cli_image_run run;
    rad_image *standard_error = NULL;
    rad_pathtrace_report report = {0};
    if (cli_ranks_begin() > 1 && rad_rank() != 0)
        s.trace.progress = NULL; /* rank 0 shows its own tiles' progress */
    rad_status status = cli_image_run_begin(&run, s.scene_path, &s.view, &error);
    if (status == RAD_OK)
        status = cli_apply_two_sided(&s.two_sided, run.scene, &error);
    if (status == RAD_OK && !rad_scene_has_emitter(run.scene) && run.scene->light_count == 0 &&
        rad_rank() == 0) /* once per job */
        cli_warn("%s: no surface emits light (no material with non-zero Ke) and no light "
                 "source is given: the image will be black (--emit NAME=R,G,B makes a surface "
                 "a light; --point, --spot, --sun, --sky add sources)",
                 run.scene->source);
    if (status == RAD_OK && (s.error_path || s.shared.stats_path))
        status = rad_image_create(s.view.width, s.view.height, &standard_error, &error);
    if (!cli_ranks_ok(status, &error))
        goto fail;
    status = rad_pathtrace(run.scene, &run.camera, &s.trace, run.image, standard_error, &report,
                           &error);
    if (!cli_ranks_ok(status, &error))
        goto fail;
    rad_rank_report rank_report = {report.rank_tiles, report.rank_seconds, 0, 0};
    double imbalance = 1;
    if (!cli_ranks_summary(&rank_report, "tiles", &imbalance, &error))
        goto fail;
    if (rad_rank() != 0) /* rank 0 has the whole image and writes it */
        goto done;
    status = cli_image_run_write(&run, output, &s.view, &error);
    if (status == RAD_OK && s.error_path)
        status = rad_image_write(standard_error, s.error_path,
                                 &(rad_image_write_options){.exr_float = s.view.write.exr_float},
                                 &error);
    if (status != RAD_OK)
        goto fail;
    run.t_write = rad_clock_seconds();
    uint32_t spp = s.trace.samples_per_pixel ? s.trace.samples_per_pixel
                                             : RAD_DEFAULT_PATHTRACE_SPP;
    double rays_per_second = report.seconds > 0 ? report.rays / report.seconds : 0;

    rad_rgb mean = image_mean(run.image);
    cli_stats stats;
    cli_image_run_stats(&run, &s.shared, spp, &stats);
    stats_integer(&stats, "max_depth", s.trace.max_depth);
    stats_integer(&stats, "rays_cast", report.rays);
    stats_number(&stats, "rays_per_second", rays_per_second);
    stats_number(&stats, "mean_radiance_r", mean.r);
    stats_number(&stats, "mean_radiance_g", mean.g);
    stats_number(&stats, "mean_radiance_b", mean.b);
    if (standard_error)
        stats_number(&stats, "rms_standard_error", rms_standard_error(standard_error));
    cli_image_run_times(&run, &stats);
    if (rad_rank_count() > 1) {
        stats_integer(&stats, "ranks", (unsigned long long)rad_rank_count());
        stats_number(&stats, "load_imbalance", imbalance);
    }
    exit_code = cli_finish(&stats, s.shared.stats_path,
                           "%u samples per pixel, %.1f M rays (%.1f M/s), %.2f s: wrote %s%s%s",
                           spp, report.rays / 1e6, rays_per_second / 1e6, run.t_write - run.t0,
                           output, s.error_path ? " and " : "", s.error_path ? s.error_path : "");
    goto done;
fail:
    exit_code = cli_ranks_failed(&error);
done:
    cli_progress_end();
    rad_image_destroy(standard_error);
    cli_image_run_free(&run);
    return cli_ranks_end(exit_code);
}
