/*
 * cmd_render.c - `radiosity render [SCENE] -o OUT [options]`: the whole pipeline, from a
 * scene (or the built-in Cornell box) to an image.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <stdio.h>

#include "cli.h"
#include "cli_ranks.h"

static const char usage[] =
    "usage: radiosity render [SCENE] -o OUT [options]\n"
    "\n"
    "Solves the radiosity of SCENE (an OBJ+MTL or any file Assimp reads; none = the\n"
    "built-in Cornell box with its official camera) and renders it to OUT. OUT's extension\n"
    "picks the format: .png (exposure, tone map, sRGB 8-bit), .hdr (Radiance RGBE), .pfm\n"
    "(portable float map) or .exr (OpenEXR); .hdr, .pfm and .exr hold linear radiance.\n"
    "With --solution FILE nothing is solved: the saved solution of the same scene is\n"
    "rendered from any camera.\n"
    "\n"
    "Camera (default: the scene's camera, or a view of the whole scene from -z):\n"
    "  --eye X,Y,Z  --target X,Y,Z  --up X,Y,Z  --fov DEG (vertical)   --size WxH (512x512)\n"
    "  --spp N              samples per pixel, stratified, box filter (default 16, at\n"
    "                       most 256; edge pixels: up to 256 more)\n"
    "  --exposure EV        PNG: scale radiance by 2^EV (default: automatic)\n"
    "  --exr-float          .exr: 32-bit float channels instead of half\n"
    "  --specular           the two-pass method: Ks > 0 surfaces mirror the lit scene\n"
    "  --max-depth N        mirror reflections followed with --specular (default 5)\n"
    "  --quantity illuminance  pixels: illuminance (lux) at the surface seen, not radiance\n"
    "  --false-colour       PNG in false colour with a legend; --scale LOW,HIGH, --log\n"
    "  --direct MODE        emitters' direct light: vertex (default), pixel or solution\n"
    CLI_TWO_SIDED_HELP
    CLI_SOLVE_HELP;

enum {
    OPT_SPECULAR = OPT_OWN, OPT_MAX_DEPTH, OPT_TWO_SIDED, OPT_QUANTITY, OPT_FALSE_COLOUR,
    OPT_SCALE, OPT_LOG, OPT_DIRECT, OPT_COUNT
};

static const cli_option options[OPT_COUNT] = {
    CLI_BASE_OPTIONS,
    CLI_FORMFACTOR_OPTIONS,
    CLI_VIEW_OPTIONS,
    CLI_SOLVE_OPTIONS,
    CLI_SCENE_OPTIONS,
    [OPT_SPECULAR] = {"specular", 0, false},
    [OPT_MAX_DEPTH] = {"max-depth", 0, true},
    [OPT_TWO_SIDED] = {"two-sided", 0, true},
    [OPT_QUANTITY] = {"quantity", 0, true},
    [OPT_FALSE_COLOUR] = {"false-colour", 0, false},
    [OPT_SCALE] = {"scale", 0, true},
    [OPT_LOG] = {"log", 0, false},
    [OPT_DIRECT] = {"direct", 0, true},
};

#define RENDER_MAX_SPP 256u

typedef struct render_settings {
    const char *scene_path, *output, *stats_path;
    cli_shared shared;
    cli_view view;
    cli_solve solve;
    rad_render_options render;
    bool specular; /* the two-pass method */
    bool false_colour;
    rad_false_colour_options colours;
} render_settings;

/* The false-colour legend's unit: lux (illuminance) or cd/m^2 (luminance) when every light
 * of the scene is photometric (radiosity.h, "Units."); "relative" when there is none (the
 * emitters' Ke in the file's own unit) or when one is not: a light the file gives in no
 * known unit (Collada, FBX), an environment map (its radiance in the map's unit). */
static const char *legend_unit(const rad_scene *scene, bool irradiance)
{
    bool photometric = scene->light_count > 0;
    for (uint32_t l = 0; l < scene->light_count; l++)
        photometric = photometric && !scene->lights[l].unit_unknown &&
                      scene->lights[l].type != RAD_LIGHT_ENVIRONMENT;
    return !photometric ? "relative" : irradiance ? "lx" : "cd/m^2";
}

static bool parse_settings(int argc, char **argv, render_settings *s, int *exit_code)
{
    cli_args args;
    memset(s, 0, sizeof(*s));
    if (!cli_parse_image_command("render", usage, argc, argv, options, OPT_COUNT, &args,
                                 &s->shared, &s->view, &s->scene_path, exit_code))
        return false;
    s->output = s->shared.output;
    s->stats_path = s->shared.stats_path;
    s->render.samples_per_pixel = s->view.samples_per_pixel;
    if (s->view.samples_per_pixel > RENDER_MAX_SPP) {
        cli_error("--spp: at most %u for render (16 x 16 strata; the radiosity image has no "
                  "noise to average away)",
                  RENDER_MAX_SPP);
        return false;
    }
    s->specular = args.value[OPT_SPECULAR] != NULL;
    const char *quantity = args.value[OPT_QUANTITY];
    if (quantity && strcmp(quantity, "illuminance") != 0 && strcmp(quantity, "irradiance") != 0 &&
        strcmp(quantity, "radiance") != 0 && strcmp(quantity, "luminance") != 0) {
        cli_error("--quantity: '%s' is not radiance (or luminance) or illuminance (or "
                  "irradiance)",
                  quantity);
        return false;
    }
    s->render.irradiance =
        quantity && (strcmp(quantity, "illuminance") == 0 || strcmp(quantity, "irradiance") == 0);
    const char *direct = args.value[OPT_DIRECT];
    if (direct && strcmp(direct, "vertex") != 0 && strcmp(direct, "pixel") != 0 &&
        strcmp(direct, "solution") != 0) {
        cli_error("--direct: '%s' is not vertex, pixel or solution", direct);
        return false;
    }
    s->render.direct_light = !direct                          ? RAD_DIRECT_VERTEX
                             : strcmp(direct, "pixel") == 0    ? RAD_DIRECT_PIXEL
                             : strcmp(direct, "solution") == 0 ? RAD_DIRECT_SOLUTION
                                                               : RAD_DIRECT_VERTEX;
    s->false_colour = args.value[OPT_FALSE_COLOUR] != NULL;
    s->colours.logarithmic = args.value[OPT_LOG] != NULL;
    if (args.value[OPT_SCALE]) {
        double lo, hi;
        char tail;
        if (sscanf(args.value[OPT_SCALE], "%lf,%lf%c", &lo, &hi, &tail) != 2 || !(lo >= 0) ||
            !(hi > lo) || !isfinite(hi)) {
            cli_error("--scale: '%s' is not LOW,HIGH with 0 <= LOW < HIGH", args.value[OPT_SCALE]);
            return false;
        }
        s->colours.low = lo;
        s->colours.high = hi;
    }
    if ((args.value[OPT_SCALE] || args.value[OPT_LOG]) && !s->false_colour) {
        cli_error("--scale and --log go with --false-colour");
        return false;
    }
    if (s->false_colour) {
        const char *dot = strrchr(s->output, '.');
        if (!dot || strcasecmp(dot, ".png") != 0) {
            cli_error("--false-colour: write a .png (the colours are the picture)");
            return false;
        }
        if (s->specular) {
            cli_error("--false-colour: not with --specular");
            return false;
        }
    }
    if (args.value[OPT_MAX_DEPTH]) {
        unsigned long value;
        if (!cli_parse_uint("max-depth", args.value[OPT_MAX_DEPTH], 64, &value))
            return false;
        if (value == 0) {
            cli_error("--max-depth: must be at least 1");
            return false;
        }
        s->render.max_depth = (uint32_t)value;
    }
    if (!cli_parse_solve(&args, &s->shared, &s->solve))
        return false;
    s->solve.light_at_vertices = s->render.direct_light != RAD_DIRECT_SOLUTION;
    cli_parse_two_sided(&args, OPT_TWO_SIDED, &s->solve.two_sided);
    s->render.threads = s->shared.threads;
    s->render.seed = s->shared.seed;
    s->render.progress = cli_progress;
    *exit_code = EXIT_OK;
    return true;
}

int command_render(int argc, char **argv)
{
    render_settings s;
    int exit_code;
    if (!parse_settings(argc, argv, &s, &exit_code))
        return exit_code;
    if (!cli_solve_outputs_writable(&s.shared, &s.solve))
        return EXIT_ERROR;
    char image_name[64];
    snprintf(image_name, sizeof(image_name), "the %u x %u image", s.view.width, s.view.height);
    if (!cli_memory_take(cli_image_bytes(&s.view, s.output, 1), image_name))
        return EXIT_ERROR;

    rad_error error = {0};
    rad_status status;
    cli_solved solved;
    rad_image *image = NULL;
    double t0 = rad_clock_seconds(), t_solved, t_render, t_write, imbalance = 1;

    cli_ranks_begin(); /* under mpirun: the ranks share the form factors and sweeps */
    cli_ranks_solve_quiet(&s.solve);
    status = cli_solve_scene(s.scene_path, &s.shared, &s.solve, &solved, &error);
    if (!cli_ranks_ok(status, &error) ||
        !cli_ranks_solve_summary(&solved, &imbalance, &error)) {
        exit_code = cli_ranks_failed(&error);
        goto done;
    }
    if (solved.checkpoint_stop) { /* the checkpoint holds the solve: no image */
        exit_code = cli_checkpoint_stop("render", &s.solve);
        goto done;
    }
    t_solved = rad_clock_seconds();
    rad_camera camera = cli_view_camera(&s.view, solved.scene);
    if (s.specular)
        s.render.materials = solved.scene->materials;
    s.render.scene = solved.scene;
    s.render.inputs = solved.inputs;
    cli_memory_release(); /* the image reserved up front is made now */
    status = rad_image_create(s.view.width, s.view.height, &image, &error);
    cli_progress_mark();
    /* every rank renders its share of the rows (rad_render is collective), so every rank
     * must have its image first; rank 0 writes */
    if (rad_rank_count() > 1 && !cli_ranks_ok(status, &error)) {
        exit_code = cli_ranks_failed(&error);
        goto done;
    }
    if (status == RAD_OK)
        status = rad_render(solved.mesh, solved.B, &camera, &s.render, image, &error);
    if (rad_rank_count() > 1 && !cli_ranks_ok(status, &error)) {
        exit_code = cli_ranks_failed(&error);
        goto done;
    }
    if (status != RAD_OK)
        goto fail;
    if (rad_rank() != 0) {
        exit_code = EXIT_OK;
        goto done;
    }
    t_render = rad_clock_seconds();
    if (rad_scene_has_emitter(solved.scene) || solved.scene->light_count > 0) {
        /* lit surfaces, a black image: the camera sees only backs (surfaces are one-sided),
         * as the default view from outside a closed room does */
        size_t lit = 0, values = (size_t)image->width * image->height * 3;
        for (size_t k = 0; k < values && !lit; k++)
            lit = image->rgb[k] > 0;
        if (!lit)
            cli_warn("%s: the image is black: the camera at (%g, %g, %g) sees no front of a "
                     "lit surface (from outside a closed scene only backs show; place it "
                     "inside with --eye and --target)",
                     solved.scene->source, camera.eye.x, camera.eye.y, camera.eye.z);
    }
    if (s.false_colour) {
        rad_image *coloured = NULL;
        s.colours.unit = legend_unit(solved.scene, s.render.irradiance);
        status = rad_image_false_colour(image, &s.colours, &coloured, &error);
        if (status == RAD_OK) {
            rad_image_write_options exact = {.fixed_exposure = true, .exposure = 0};
            status = rad_image_write(coloured, s.output, &exact, &error);
        }
        rad_image_destroy(coloured);
    } else
        status = rad_image_write(image, s.output, &s.view.write, &error);
    if (status != RAD_OK)
        goto fail;
    t_write = rad_clock_seconds();
    cli_stats stats;
    stats_begin(&stats);
    cli_solved_stats(&solved, &s.solve, &stats);
    stats_number(&stats, "seconds_render", t_render - t_solved);
    stats_number(&stats, "seconds_write", t_write - t_render);
    stats_number(&stats, "seconds_total", t_write - t0);
    stats_integer(&stats, "width", s.view.width);
    stats_integer(&stats, "height", s.view.height);
    if (rad_rank_count() > 1) {
        stats_integer(&stats, "ranks", (unsigned long long)rad_rank_count());
        stats_number(&stats, "load_imbalance", imbalance);
    }
    char summary[384];
    cli_solved_summary(&solved, &s.solve, summary, sizeof(summary));
    exit_code = cli_finish(&stats, s.stats_path, "%s, %.2f s: wrote %s", summary, t_write - t0,
                           s.output);
    if (exit_code == EXIT_OK && solved.report.interrupted)
        exit_code = EXIT_INTERRUPTED; /* the image is complete, of the solution so far */
    goto done;
fail:
    exit_code = cli_failed(&error);
done:
    cli_progress_end();
    rad_image_destroy(image);
    cli_solved_free(&solved); /* cli_solve_scene always leaves it freeable */
    return cli_ranks_end(exit_code);
}
