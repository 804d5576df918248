/*
 * cmd_raytrace.c - `radiosity raytrace [SCENE] -o OUT [options]`: Whitted ray tracing with
 * the Phong model, a thin client of rad_raytrace; nothing here computes light.
 *
 * cli_parse keeps one value per option (the last); --light may be given many times, so
 * after cli_parse has validated the command line, argv is walked again with the same
 * option table to collect every --light value, in order.
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
    "Surfaces are one-sided: back faces and the background are black. OUT's\n"
    "extension picks the format: .png (exposure, tone map, sRGB 8-bit), .hdr (Radiance\n"
    "RGBE), .pfm (portable float map) or .exr (OpenEXR, half float); .hdr, .pfm and .exr\n"
    "hold linear radiance.\n"
    "\n"
    "Lighting:\n"
    "  --light X,Y,Z:R,G,B  a point light at X,Y,Z of intensity R,G,B; repeat for more\n"
    "  --ambient R,G,B      ambient light Ia, reflected with Kd (default 0,0,0)\n"
    "  --light-samples N    points sampled on all emitters together (chosen by power)\n"
    "                       per shading point (default 16)\n"
    "  --max-depth N        most mirror reflections followed (default 5)\n"
    "Camera (default: the scene's camera, or a view of the whole scene from -z):\n"
    "  --eye X,Y,Z  --target X,Y,Z  --up X,Y,Z  --fov DEG (vertical)   --size WxH (512x512)\n"
    "  --spp N              samples per pixel, rounded to a square, stratified, box filter\n"
    "                       (default 4; 1 = through the pixel centre)\n"
    "  --exposure EV        PNG: scale radiance by 2^EV (default: automatic)\n"
    "  --exr-float          .exr: 32-bit float channels instead of half\n"
    "Run:\n"
    CLI_SCENE_HELP
    "  --threads N          worker threads (default: all cores)\n"
    "  --seed N             seed of every random choice (default 1)\n"
    "  --stats FILE.json    write counts, times and peak memory\n"
    "  -h, --help           this text\n";

enum { OPT_LIGHT = OPT_OWN, OPT_AMBIENT, OPT_LIGHT_SAMPLES, OPT_MAX_DEPTH, OPT_COUNT };

static const cli_option options[OPT_COUNT] = {
    CLI_BASE_OPTIONS,
    CLI_VIEW_OPTIONS,
    CLI_SCENE_OPTIONS,
    [OPT_LIGHT] = {"light", 0, true},
    [OPT_AMBIENT] = {"ambient", 0, true},
    [OPT_LIGHT_SAMPLES] = {"light-samples", 0, true},
    [OPT_MAX_DEPTH] = {"max-depth", 0, true},
};

/* Library limits the command line checks first, so that the message names the option. */
#define MAX_LIGHT_SAMPLES 65536ul
#define MAX_DEPTH (1ul << 20)

typedef struct raytrace_settings {
    const char *scene_path, *output, *stats_path;
    cli_shared shared;
    cli_view view;
    rad_point_light *lights; /* owned */
    rad_raytrace_options trace;
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

/* Every --light value in argv, in order, walking argv as cli_parse does (it has already
 * accepted the line): an option that takes a value without "=" consumes the next word. */
static bool collect_lights(int argc, char **argv, raytrace_settings *s)
{
    s->lights = calloc((size_t)(argc > 0 ? argc : 1), sizeof(*s->lights));
    if (!s->lights) {
        cli_error("out of memory");
        return false;
    }
    uint32_t count = 0;
    for (int a = 0; a < argc; a++) {
        const char *arg = argv[a];
        if (arg[0] != '-' || arg[1] == 0)
            continue; /* positional */
        const char *value = NULL;
        int k = -1;
        if (arg[1] == '-') {
            const char *eq = strchr(arg + 2, '=');
            size_t length = eq ? (size_t)(eq - arg - 2) : strlen(arg + 2);
            for (int o = 0; o < OPT_COUNT; o++)
                if (options[o].name && strlen(options[o].name) == length &&
                    strncmp(options[o].name, arg + 2, length) == 0)
                    k = o;
            value = eq ? eq + 1 : NULL;
        } else {
            for (int o = 0; o < OPT_COUNT; o++)
                if (options[o].name && options[o].short_name == arg[1] && arg[2] == 0)
                    k = o;
        }
        if (k < 0 || !options[k].takes_value)
            continue;
        if (!value && a + 1 < argc)
            value = argv[++a];
        if (k == OPT_LIGHT && value && !parse_light(value, &s->lights[count++]))
            return false;
    }
    s->trace.lights = s->lights;
    s->trace.light_count = count;
    return true;
}

static bool parse_settings(int argc, char **argv, raytrace_settings *s, int *exit_code)
{
    cli_args args;
    memset(s, 0, sizeof(*s));
    if (!cli_parse_image_command("raytrace", usage, argc, argv, options, OPT_COUNT, &args,
                                 &s->shared, &s->view, &s->scene_path, exit_code))
        return false;
    s->output = s->shared.output;
    s->stats_path = s->shared.stats_path;
    if (!collect_lights(argc, argv, s))
        return false;
    if (args.value[OPT_AMBIENT] && !parse_rgb("ambient", args.value[OPT_AMBIENT], &s->trace.ambient))
        return false;
    unsigned long value;
    if (args.value[OPT_LIGHT_SAMPLES]) {
        if (!cli_parse_uint("light-samples", args.value[OPT_LIGHT_SAMPLES], MAX_LIGHT_SAMPLES,
                            &value))
            return false;
        if (value == 0) {
            cli_error("--light-samples: must be at least 1");
            return false;
        }
        s->trace.light_samples = (uint32_t)value;
    }
    if (args.value[OPT_MAX_DEPTH]) {
        if (!cli_parse_uint("max-depth", args.value[OPT_MAX_DEPTH], MAX_DEPTH, &value))
            return false;
        if (value == 0) {
            cli_error("--max-depth: must be at least 1");
            return false;
        }
        s->trace.max_depth = (uint32_t)value;
    }
    s->trace.samples_per_pixel = s->view.samples_per_pixel; /* 0 = the library's 4 */
    s->trace.seed = s->shared.seed;
    s->trace.threads = s->shared.threads;
    s->trace.progress = cli_progress;
    *exit_code = EXIT_OK;
    return true;
}

int command_raytrace(int argc, char **argv)
{
    raytrace_settings s;
    memset(&s, 0, sizeof(s));
    int exit_code;
    rad_error error = {0};
    rad_status status;
    rad_scene *scene = NULL;
    rad_image *image = NULL;
    double t0 = cli_now(), t_load, t_trace, t_write;

    if (!parse_settings(argc, argv, &s, &exit_code))
        goto done;
    if (!cli_output_writable(s.output) || (s.stats_path && !cli_output_writable(s.stats_path))) {
        exit_code = EXIT_ERROR;
        goto done;
    }

    status = cli_load_scene(s.scene_path, &scene, &error);
    if (status != RAD_OK)
        goto fail;
    t_load = cli_now();
    bool emitters = rad_scene_has_emitter(scene);
    bool ambient = s.trace.ambient.r > 0 || s.trace.ambient.g > 0 || s.trace.ambient.b > 0;
    if (!emitters && s.trace.light_count == 0)
        cli_warn("%s: no light: no --light given and no surface emits (Ke)%s", scene->source,
                 ambient ? ": only the ambient term lights the image" : ": the image will be black");
    rad_camera camera = cli_view_camera(&s.view, scene);

    status = rad_image_create(s.view.width, s.view.height, &image, &error);
    if (status == RAD_OK)
        status = rad_raytrace(scene, &camera, &s.trace, image, &error);
    if (status != RAD_OK)
        goto fail;
    cli_progress_end();
    t_trace = cli_now();
    status = rad_image_write(image, s.output, &s.view.write, &error);
    if (status != RAD_OK)
        goto fail;
    t_write = cli_now();
    uint32_t strata = (uint32_t)lround(sqrt((double)(s.trace.samples_per_pixel ? s.trace.samples_per_pixel : 4)));
    uint32_t spp = strata * strata; /* rounded to a square as the library does */
    if (cli_progress_enabled()) /* a summary for a person watching; quiet in scripts */
        fprintf(stderr, "radiosity: %u point lights%s, %.2f s: wrote %s\n",
                s.trace.light_count, emitters ? " and the emitting surfaces" : "",
                t_write - t0, s.output);

    if (s.stats_path) {
        cli_stats stats;
        stats_begin(&stats);
        stats_string(&stats, "scene", scene->source);
        stats_integer(&stats, "triangles", scene->triangle_count);
        stats_integer(&stats, "width", s.view.width);
        stats_integer(&stats, "height", s.view.height);
        stats_integer(&stats, "samples_per_pixel", spp);
        stats_integer(&stats, "point_lights", s.trace.light_count);
        stats_bool(&stats, "area_lights", emitters);
        stats_integer(&stats, "light_samples",
                      s.trace.light_samples ? s.trace.light_samples : 16);
        stats_integer(&stats, "max_depth", s.trace.max_depth ? s.trace.max_depth : 5);
        stats_integer(&stats, "seed", s.trace.seed);
        stats_integer(&stats, "threads_requested", (unsigned long long)s.trace.threads);
        stats_number(&stats, "seconds_load", t_load - t0);
        stats_number(&stats, "seconds_trace", t_trace - t_load);
        stats_number(&stats, "seconds_write", t_write - t_trace);
        stats_number(&stats, "seconds_total", t_write - t0);
        stats_integer(&stats, "peak_memory_bytes", rad_peak_memory_bytes());
        if (!stats_write(&stats, s.stats_path))
            exit_code = EXIT_ERROR;
    }
    goto done;
fail:
    cli_error("%s", error.message);
    exit_code = EXIT_ERROR;
done:
    cli_progress_end();
    rad_image_destroy(image);
    rad_scene_destroy(scene);
    free(s.lights);
    return exit_code;
}
