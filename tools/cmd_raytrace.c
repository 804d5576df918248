/*
 * cmd_raytrace.c - `radiosity raytrace [SCENE] -o OUT [options]`: Whitted ray tracing with
 * the Phong model, a thin client of rad_raytrace; nothing here computes light.
 */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

static const char usage[] =
    "usage: radiosity raytrace [SCENE] -o OUT [options]\n"
    "\n"
    "Renders SCENE (an OBJ+MTL or any file Assimp reads; none = the built-in Cornell box\n"
    "with its official camera) by Whitted ray tracing with the Phong model:\n"
    "  I = Ke + Kd Ia + sum over lights (Kd <N,L> + Ks <V,R>^Ns) I_L S_L + Ks I_R\n"
    "with Kd, Ks, Ns and Ke from the materials (MTL), S_L a shadow ray and I_R the radiance\n"
    "seen in the mirror direction. Point lights have no distance falloff (the classic\n"
    "model). The scene's emitting surfaces are area lights, sampled for soft shadows: each\n"
    "sample adds (Kd + Ks <V,R>^Ns)/pi Le cos cos' / r^2 / pdf (Phong read as a BRDF).\n"
    "Surfaces are one-sided (back faces and the background are black) unless two-sided\n"
    "(--two-sided, glTF doubleSided): their back is shaded as their front. OUT's\n"
    "extension picks the format: .png (exposure, tone map, sRGB 8-bit), .hdr (Radiance\n"
    "RGBE), .pfm (portable float map) or .exr (OpenEXR, half float); .hdr, .pfm and .exr\n"
    "hold linear radiance.\n"
    "\n"
    "Lighting:\n"
    "  --light X,Y,Z:R,G,B  a point light at X,Y,Z of intensity R,G,B; repeat for more\n"
    "  --ambient R,G,B      ambient light Ia, reflected with Kd (default 0,0,0)\n"
    "  --light-samples N    points sampled on all emitters together (chosen by power)\n"
    "                       per shading point, and directions toward a sky or environment\n"
    "                       (default " CLI_STR(RAD_DEFAULT_LIGHT_SAMPLES) ")\n"
    "  --max-depth N        most mirror reflections followed (default "
    CLI_STR(RAD_DEFAULT_MAX_DEPTH) ")\n"
    "  --max-memory SIZE    bytes the whole run may hold (K, M, G): the image (refused\n"
    "                       at once when it cannot fit), scene, BVH, buffers; anything\n"
    "                       else past it ends the run with an error\n"
    CLI_CAMERA_HELP
    "  --spp N              samples per pixel, rounded to a square, stratified, box filter\n"
    "                       (default " CLI_STR(RAD_DEFAULT_RAYTRACE_SPP) "; 1 = through the pixel centre)\n"
    CLI_IMAGE_FILE_HELP
    "Run:\n"
    CLI_TWO_SIDED_HELP
    CLI_BASE_HELP("counts, times and peak memory");

enum { OPT_LIGHT = OPT_OWN, OPT_AMBIENT, OPT_LIGHT_SAMPLES, OPT_MAX_DEPTH, OPT_TWO_SIDED,
       OPT_COUNT };

static const cli_option options[OPT_COUNT] = {
    CLI_BASE_OPTIONS,
    CLI_VIEW_OPTIONS,
    CLI_SCENE_OPTIONS,
    [OPT_MAX_MEMORY] = {"max-memory", 0, true},
    [OPT_LIGHT] = {"light", 0, true},
    [OPT_AMBIENT] = {"ambient", 0, true},
    [OPT_LIGHT_SAMPLES] = {"light-samples", 0, true},
    [OPT_MAX_DEPTH] = {"max-depth", 0, true},
    [OPT_TWO_SIDED] = {"two-sided", 0, true},
};

/* Library limits the command line checks first, so that the message names the option. */
#define MAX_LIGHT_SAMPLES 65536ul
#define MAX_DEPTH (1ul << 20)

typedef struct raytrace_settings {
    const char *scene_path;
    cli_shared shared;
    cli_view view;
    rad_point_light *lights; /* owned */
    cli_two_sided two_sided;
    rad_raytrace_options trace;
    uint64_t max_memory; /* --max-memory, 0 = none */
} raytrace_settings;

/* Parses `count` comma-separated finite numbers from text up to `end` (exclusive). */
static bool parse_numbers(const char *text, const char *end, double *out, int count)
{
    const char *cursor = text;
    for (int k = 0; k < count; k++) {
        char *stop;
        errno = 0;
        out[k] = strtod(cursor, &stop);
        if (stop == cursor || errno != 0 || !isfinite(out[k]))
            return false;
        if (k < count - 1 ? *stop != ',' : stop != end)
            return false;
        cursor = stop + 1;
    }
    return true;
}

/* "R,G,B", each finite and not negative. */
static bool parse_rgb(const char *name, const char *text, rad_rgb *out)
{
    double v[3];
    if (!parse_numbers(text, text + strlen(text), v, 3)) {
        cli_error("--%s: '%s' is not R,G,B", name, text);
        return false;
    }
    if (v[0] < 0 || v[1] < 0 || v[2] < 0) {
        cli_error("--%s: '%s': a colour must not be negative", name, text);
        return false;
    }
    *out = (rad_rgb){v[0], v[1], v[2]};
    return true;
}

/* "X,Y,Z:R,G,B": a position, then a non-negative intensity. */
static bool parse_light(const char *text, rad_point_light *light)
{
    const char *colon = strchr(text, ':');
    double p[3], c[3];
    if (!colon || !parse_numbers(text, colon, p, 3) ||
        !parse_numbers(colon + 1, colon + 1 + strlen(colon + 1), c, 3)) {
        cli_error("--light: '%s' is not X,Y,Z:R,G,B (a position, then an intensity)", text);
        return false;
    }
    if (c[0] < 0 || c[1] < 0 || c[2] < 0) {
        cli_error("--light: '%s': the intensity must not be negative", text);
        return false;
    }
    light->position = (rad_vec3){p[0], p[1], p[2]};
    light->intensity = (rad_rgb){c[0], c[1], c[2]};
    return true;
}

/* Every --light, in command-line order. */
static bool collect_lights(const cli_args *args, raytrace_settings *s)
{
    int count = cli_value_count(args, OPT_LIGHT), cursor = 0;
    s->lights = rad_alloc_array((size_t)(count > 0 ? count : 1), sizeof(*s->lights));
    if (!s->lights) {
        cli_error("out of memory");
        return false;
    }
    for (int k = 0; k < count; k++)
        if (!parse_light(cli_next_value(args, OPT_LIGHT, &cursor), &s->lights[k]))
            return false;
    s->trace.lights = s->lights;
    s->trace.light_count = (uint32_t)count;
    return true;
}

static bool parse_settings(int argc, char **argv, raytrace_settings *s, int *exit_code)
{
    cli_args args;
    memset(s, 0, sizeof(*s));
    if (!cli_parse_image_command("raytrace", usage, argc, argv, options, OPT_COUNT, &args,
                                 &s->shared, &s->view, &s->scene_path, exit_code))
        return false;
    if (!collect_lights(&args, s))
        return false;
    cli_parse_two_sided(&args, OPT_TWO_SIDED, &s->two_sided);
    if (args.value[OPT_AMBIENT] && !parse_rgb("ambient", args.value[OPT_AMBIENT], &s->trace.ambient))
        return false;
    if (!cli_parse_count("light-samples", args.value[OPT_LIGHT_SAMPLES], 1, MAX_LIGHT_SAMPLES,
                         &s->trace.light_samples) ||
        !cli_parse_count("max-depth", args.value[OPT_MAX_DEPTH], 1, MAX_DEPTH,
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

int command_raytrace(int argc, char **argv)
{
    raytrace_settings s;
    int exit_code;
    if (!parse_settings(argc, argv, &s, &exit_code)) {
        free(s.lights);
        return exit_code;
    }
    char image_name[64];
    snprintf(image_name, sizeof(image_name), "the %u x %u image", s.view.width, s.view.height);
    cli_memory_budget(s.max_memory);
    if (!cli_outputs_writable((const char *[]){s.shared.output, s.shared.stats_path}, 2) ||
        !cli_memory_take(cli_image_bytes(&s.view, s.shared.output, 1), image_name)) {
        free(s.lights);
        return EXIT_ERROR;
    }

    rad_error error = {0};
    cli_image_run run;
    rad_status status = cli_image_run_begin(&run, s.scene_path, &s.view, &error);
    if (status == RAD_OK)
        status = cli_apply_two_sided(&s.two_sided, run.scene, &error);
    bool emitters = status == RAD_OK &&
                    (rad_scene_has_emitter(run.scene) || run.scene->light_count > 0);
    bool ambient = s.trace.ambient.r > 0 || s.trace.ambient.g > 0 || s.trace.ambient.b > 0;
    if (status == RAD_OK && !emitters && s.trace.light_count == 0)
        cli_warn("%s: no light: no --light given, no surface emits (Ke) and no light source%s", run.scene->source,
                 ambient ? ": only the ambient term lights the image" : ": the image will be black");
    if (status == RAD_OK)
        status = rad_raytrace(run.scene, &run.camera, &s.trace, run.image, &error);
    if (status == RAD_OK)
        status = cli_image_run_write(&run, s.shared.output, &s.view, &error);
    if (status != RAD_OK)
        goto fail;
    uint32_t strata = (uint32_t)lround(sqrt((double)(
        s.trace.samples_per_pixel ? s.trace.samples_per_pixel : RAD_DEFAULT_RAYTRACE_SPP)));
    uint32_t spp = strata * strata; /* rounded to a square as the library does */

    cli_stats stats;
    cli_image_run_stats(&run, &s.shared, spp, &stats);
    stats_integer(&stats, "point_lights", s.trace.light_count);
    stats_bool(&stats, "area_lights", emitters);
    stats_integer(&stats, "light_samples",
                  s.trace.light_samples ? s.trace.light_samples : RAD_DEFAULT_LIGHT_SAMPLES);
    stats_integer(&stats, "max_depth",
                  s.trace.max_depth ? s.trace.max_depth : RAD_DEFAULT_MAX_DEPTH);
    cli_image_run_times(&run, &stats);
    exit_code = cli_finish(&stats, s.shared.stats_path,
                           "%u point lights%s, %u samples per pixel, %.2f s: wrote %s",
                           s.trace.light_count, emitters ? " and the emitting surfaces" : "",
                           spp, run.t_write - run.t0, s.shared.output);
    goto done;
fail:
    exit_code = cli_failed(&error);
done:
    cli_progress_end();
    cli_image_run_free(&run);
    free(s.lights);
    return exit_code;
}
