/*
 * cli.c - argument parsing, messages, progress and the --stats report, see cli.h.
 */
#include "cli.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

/* One line on stderr: "radiosity: " + prefix + the formatted text. */
static void vmessage(const char *prefix, const char *format, va_list args)
    __attribute__((format(printf, 2, 0)));
static void vmessage(const char *prefix, const char *format, va_list args)
{
    cli_progress_end();
    fprintf(stderr, "radiosity: %s", prefix);
    vfprintf(stderr, format, args);
    fputc('\n', stderr);
}

void cli_error(const char *format, ...)
{
    va_list args;
    va_start(args, format);
    vmessage("", format, args);
    va_end(args);
}

void cli_warn(const char *format, ...)
{
    va_list args;
    va_start(args, format);
    vmessage("warning: ", format, args);
    va_end(args);
}

int cli_failed(const rad_error *error)
{
    /* out of memory under --max-memory: say it was the budget, and how much was asked */
    char refusal[192];
    if (error->status == RAD_ERR_NOMEM && strncmp(error->message, "--max-memory", 12) != 0 &&
        rad_memory_budget_refusal(refusal, sizeof(refusal)))
        cli_error("%s: %s", error->message, refusal);
    else
        cli_error("%s", error->message);
    return EXIT_ERROR;
}

void cli_log(void *user, const char *message)
{
    (void)user;
    cli_progress_end();
    fprintf(stderr, "radiosity: warning: %s\n", message);
}

static int find_option(const cli_option *options, int count, const char *name, char short_name)
{
    for (int k = 0; k < count; k++)
        if (!options[k].name)
            continue; /* a group this command does not take */
        else if ((name && strcmp(options[k].name, name) == 0) ||
            (!name && short_name && options[k].short_name == short_name))
            return k;
    return -1;
}

bool cli_parse(const char *command, int argc, char **argv, const cli_option *options,
               int option_count, cli_args *args)
{
    memset(args, 0, sizeof(*args));
    for (int a = 0; a < argc; a++) {
        const char *arg = argv[a];
        if (arg[0] != '-' || arg[1] == 0) {
            if (args->positional_count == (int)(sizeof(args->positional) / sizeof(args->positional[0]))) {
                cli_error("%s: too many arguments (see 'radiosity %s --help')", command, command);
                return false;
            }
            args->positional[args->positional_count++] = arg;
            continue;
        }
        int k;
        const char *inline_value = NULL;
        char name[64];
        if (arg[1] == '-') {
            const char *eq = strchr(arg + 2, '=');
            size_t length = eq ? (size_t)(eq - arg - 2) : strlen(arg + 2);
            if (length >= sizeof(name))
                length = sizeof(name) - 1;
            memcpy(name, arg + 2, length);
            name[length] = 0;
            inline_value = eq ? eq + 1 : NULL;
            k = find_option(options, option_count, name, 0);
        } else {
            snprintf(name, sizeof(name), "%s", arg + 1);
            k = arg[2] == 0 ? find_option(options, option_count, NULL, arg[1]) : -1;
        }
        if (k < 0) {
            cli_error("%s: unknown option '%s' (see 'radiosity %s --help')", command, arg,
                      command);
            return false;
        }
        if (!options[k].takes_value) {
            if (inline_value) {
                cli_error("%s: option '--%s' takes no value", command, options[k].name);
                return false;
            }
            args->value[k] = "";
            continue;
        }
        if (!inline_value) {
            if (a + 1 >= argc) {
                cli_error("%s: option '%s' needs a value (see 'radiosity %s --help')", command,
                          arg, command);
                return false;
            }
            inline_value = argv[++a];
        }
        args->value[k] = inline_value;
        if (args->given_count == CLI_MAX_GIVEN) {
            cli_error("%s: more than %d options", command, CLI_MAX_GIVEN);
            return false;
        }
        args->given_value[args->given_count] = inline_value;
        args->given_option[args->given_count++] = k;
    }
    return true;
}

const char *cli_next_value(const cli_args *args, int option, int *cursor)
{
    for (; *cursor < args->given_count; (*cursor)++)
        if (args->given_option[*cursor] == option)
            return args->given_value[(*cursor)++];
    return NULL;
}

int cli_value_count(const cli_args *args, int option)
{
    int count = 0, cursor = 0;
    while (cli_next_value(args, option, &cursor))
        count++;
    return count;
}

bool cli_parse_double(const char *name, const char *text, double *out)
{
    char *end;
    errno = 0;
    double value = strtod(text, &end);
    if (end == text || *end != 0 || errno != 0 || !isfinite(value)) {
        cli_error("--%s: '%s' is not a number", name, text);
        return false;
    }
    *out = value;
    return true;
}

bool cli_parse_positive(const char *name, const char *text, double *out)
{
    double value;
    if (!cli_parse_double(name, text, &value))
        return false;
    if (!(value > 0)) {
        cli_error("--%s: must be positive", name);
        return false;
    }
    *out = value;
    return true;
}

bool cli_parse_uint(const char *name, const char *text, unsigned long max, unsigned long *out)
{
    char *end;
    errno = 0;
    unsigned long value = strtoul(text, &end, 10);
    if (end == text || *end != 0 || errno != 0 || text[0] == '-' || value > max) {
        cli_error("--%s: '%s' is not a whole number from 0 to %lu", name, text, max);
        return false;
    }
    *out = value;
    return true;
}

bool cli_parse_count(const char *name, const char *text, uint32_t min, uint32_t max,
                     uint32_t *out)
{
    unsigned long value;
    if (!text)
        return true;
    if (!cli_parse_uint(name, text, max, &value))
        return false;
    if (value < min) {
        cli_error("--%s: must be at least %u", name, (unsigned)min);
        return false;
    }
    *out = (uint32_t)value;
    return true;
}

bool cli_parse_vec3(const char *name, const char *text, rad_vec3 *out)
{
    double v[3];
    const char *cursor = text;
    for (int k = 0; k < 3; k++) {
        char *end;
        errno = 0;
        v[k] = strtod(cursor, &end);
        if (end == cursor || errno != 0 || !isfinite(v[k]) || *end != (k < 2 ? ',' : 0)) {
            cli_error("--%s: '%s' is not X,Y,Z", name, text);
            return false;
        }
        cursor = end + 1;
    }
    *out = (rad_vec3){v[0], v[1], v[2]};
    return true;
}

bool cli_parse_size(const char *name, const char *text, uint32_t *width, uint32_t *height)
{
    char *end;
    errno = 0;
    unsigned long w = strtoul(text, &end, 10);
    if (end == text || (*end != 'x' && *end != 'X') || text[0] == '-')
        goto bad;
    const char *rest = end + 1;
    unsigned long h = strtoul(rest, &end, 10);
    if (end == rest || *end != 0 || errno != 0 || rest[0] == '-' || w == 0 || h == 0 ||
        w > 32768 || h > 32768)
        goto bad;
    *width = (uint32_t)w;
    *height = (uint32_t)h;
    return true;
bad:
    cli_error("--%s: '%s' is not WIDTHxHEIGHT (1 to 32768 each)", name, text);
    return false;
}

/* The --emit / --albedo options, for cli_load_scene: one command runs per process. */
typedef struct material_override {
    char name[128];
    rad_rgb value;
    bool is_emission;
} material_override;

static material_override overrides[CLI_MAX_GIVEN];
static int override_count;

/* --quiet, for cli_summary. */
static bool quiet;

/* NAME=R,G,B; NAME may itself hold '=' (the last one splits). */
static bool parse_override(const char *option, const char *text, material_override *out)
{
    const char *eq = strrchr(text, '=');
    rad_vec3 v;
    if (!eq || eq == text || (size_t)(eq - text) >= sizeof(out->name)) {
        cli_error("--%s: '%s' is not NAME=R,G,B", option, text);
        return false;
    }
    if (!cli_parse_vec3(option, eq + 1, &v))
        return false;
    snprintf(out->name, sizeof(out->name), "%.*s", (int)(eq - text), text);
    out->value = (rad_rgb){v.x, v.y, v.z};
    out->is_emission = strcmp(option, "emit") == 0;
    bool in_range = v.x >= 0 && v.y >= 0 && v.z >= 0 &&
                    (out->is_emission || (v.x <= 1 && v.y <= 1 && v.z <= 1));
    if (!in_range) {
        cli_error("--%s: '%s': %s", option, text,
                  out->is_emission ? "radiance must be >= 0" : "albedo must be in [0,1]");
        return false;
    }
    return true;
}

bool cli_parse_shared(const cli_args *args, cli_shared *shared)
{
    /* --emit and --albedo apply in command-line order, mixed */
    override_count = 0;
    for (int k = 0; k < args->given_count; k++) {
        int option = args->given_option[k];
        if (option != OPT_EMIT && option != OPT_ALBEDO)
            continue;
        if (!parse_override(option == OPT_EMIT ? "emit" : "albedo", args->given_value[k],
                            &overrides[override_count]))
            return false;
        override_count++;
    }
    if (!cli_parse_lights(args))
        return false;
    quiet = args->value[OPT_QUIET] != NULL;
    unsigned long value;
    memset(shared, 0, sizeof(*shared));
    shared->seed = CLI_DEFAULT_SEED;
    shared->output = args->value[OPT_OUTPUT];
    shared->stats_path = args->value[OPT_STATS];
    if (args->value[OPT_PATCH_SIZE]) {
        if (!cli_parse_positive("patch-size", args->value[OPT_PATCH_SIZE], &shared->patch_size))
            return false;
    }
    if (args->value[OPT_SHADOW_LEVELS]) {
        uint32_t levels = 0;
        if (!cli_parse_count("shadow-levels", args->value[OPT_SHADOW_LEVELS], 0,
                             RAD_SHADOW_LEVELS_MAX, &levels))
            return false;
        shared->shadow_levels = levels == 0 ? -1 : (int)levels;
    }
    if (args->value[OPT_PROXIMITY_LEVELS]) {
        uint32_t levels = 0;
        if (!cli_parse_count("proximity-levels", args->value[OPT_PROXIMITY_LEVELS], 0,
                             RAD_PROXIMITY_LEVELS_MAX, &levels))
            return false;
        shared->proximity_levels = levels == 0 ? -1 : (int)levels;
    }
    if (!cli_parse_count("visibility-rays", args->value[OPT_VISIBILITY_RAYS], 0, 256,
                         &shared->formfactor.visibility_rays) ||
        !cli_parse_count("quadrature", args->value[OPT_QUADRATURE], 0, 8,
                         &shared->formfactor.quadrature))
        return false;
    if (args->value[OPT_THREADS]) {
        if (!cli_parse_uint("threads", args->value[OPT_THREADS], 1024, &value))
            return false;
        shared->threads = (int)value;
    }
    if (args->value[OPT_SEED] &&
        !cli_parse_uint("seed", args->value[OPT_SEED], ULONG_MAX, &shared->seed))
        return false;
    CLI_SET_RUN_OPTIONS(shared->formfactor, *shared);
    return true;
}

bool cli_parse_view(const cli_args *args, cli_view *view)
{
    memset(view, 0, sizeof(*view));
    view->width = CLI_DEFAULT_WIDTH;
    view->height = CLI_DEFAULT_HEIGHT;
    if ((args->value[OPT_EYE] && !cli_parse_vec3("eye", args->value[OPT_EYE], &view->camera.eye)) ||
        (args->value[OPT_TARGET] &&
         !cli_parse_vec3("target", args->value[OPT_TARGET], &view->camera.target)) ||
        (args->value[OPT_UP] && !cli_parse_vec3("up", args->value[OPT_UP], &view->camera.up)) ||
        (args->value[OPT_FOV] &&
         !cli_parse_double("fov", args->value[OPT_FOV], &view->camera.fov_degrees)) ||
        (args->value[OPT_SIZE] &&
         !cli_parse_size("size", args->value[OPT_SIZE], &view->width, &view->height)))
        return false;
    view->has_eye = args->value[OPT_EYE] != NULL;
    view->has_target = args->value[OPT_TARGET] != NULL;
    view->has_up = args->value[OPT_UP] != NULL;
    view->has_fov = args->value[OPT_FOV] != NULL;
    if (view->has_fov && !(view->camera.fov_degrees > 0 && view->camera.fov_degrees < 180)) {
        cli_error("--fov: must be between 0 and 180 degrees");
        return false;
    }
    if (!cli_parse_count("spp", args->value[OPT_SPP], 1, 1u << 20, &view->samples_per_pixel))
        return false;
    if (args->value[OPT_EXPOSURE]) {
        if (!cli_parse_double("exposure", args->value[OPT_EXPOSURE], &view->write.exposure))
            return false;
        view->write.fixed_exposure = true;
    }
    view->write.exr_float = args->value[OPT_EXR_FLOAT] != NULL;
    return true;
}

rad_camera cli_view_camera(const cli_view *view, const rad_scene *scene)
{
    rad_camera camera = scene->has_camera ? scene->camera : rad_scene_default_camera(scene);
    if (view->has_eye)
        camera.eye = view->camera.eye;
    if (view->has_target)
        camera.target = view->camera.target;
    if (view->has_up)
        camera.up = view->camera.up;
    if (view->has_fov)
        camera.fov_degrees = view->camera.fov_degrees;
    return camera;
}

bool cli_parse_bytes(const char *name, const char *text, uint64_t *out)
{
    char *end = NULL;
    double value = strtod(text, &end);
    double scale = 1;
    if (end && *end) {
        if ((end[0] == 'K' || end[0] == 'k') && !end[1])
            scale = 1024.0;
        else if ((end[0] == 'M' || end[0] == 'm') && !end[1])
            scale = 1024.0 * 1024;
        else if ((end[0] == 'G' || end[0] == 'g') && !end[1])
            scale = 1024.0 * 1024 * 1024;
        else
            end = NULL;
    }
    if (!end || end == text || !(value >= 1) || !(value * scale < 1.8e19)) {
        cli_error("--%s: '%s' is not a size in bytes (a number, optionally followed by K, M "
                  "or G)",
                  name, text);
        return false;
    }
    *out = (uint64_t)(value * scale);
    return true;
}

uint64_t cli_image_bytes(const cli_view *view, const char *path, int images)
{
    uint64_t pixels = (uint64_t)view->width * view->height;
    const char *dot = path ? strrchr(path, '.') : NULL;
    bool png_auto = dot && strcasecmp(dot, ".png") == 0 && !view->write.fixed_exposure;
    return pixels * (uint64_t)images * 3 * sizeof(float) + (png_auto ? pixels * sizeof(double) : 0);
}

/* What cli_memory_take reserved and cli_memory_release gives back. */
static uint64_t memory_reserved;

void cli_memory_budget(uint64_t bytes) { rad_memory_budget_set(bytes); }

bool cli_memory_take(uint64_t need, const char *what)
{
    if (rad_memory_budget() == 0)
        return true;
    rad_error error = {0};
    if (rad_memory_budget_need(need, what, &error) != RAD_OK) {
        cli_error("%s", error.message);
        return false;
    }
    rad_memory_budget_reserve(need);
    memory_reserved += need;
    return true;
}

void cli_memory_release(void)
{
    rad_memory_budget_unreserve(memory_reserved);
    memory_reserved = 0;
}

bool cli_image_output_ok(const char *path)
{
    const char *dot = strrchr(path, '.');
    if (dot && (strcasecmp(dot, ".png") == 0 || strcasecmp(dot, ".hdr") == 0 ||
                strcasecmp(dot, ".pfm") == 0 || strcasecmp(dot, ".exr") == 0))
        return true;
    cli_error("%s: unknown image format (use .png, .hdr, .pfm or .exr)", path);
    return false;
}

bool cli_begin(const char *command, const char *usage, int argc, char **argv,
               const cli_option *options, int option_count, cli_args *args,
               cli_shared *shared, int *exit_code)
{
    *exit_code = EXIT_USAGE;
    if (!cli_parse(command, argc, argv, options, option_count, args))
        return false;
    if (args->value[OPT_HELP]) {
        fputs(usage, stdout);
        if (options[OPT_SHADOW_LEVELS].name)
            fputs("\nMeshing:\n" CLI_MESH_HELP, stdout);
        if (options[OPT_RECORD].name)
            fputs("\nConvergence:\n" CLI_CONVERGENCE_HELP, stdout);
        if (options[OPT_SOLVE_CHECKPOINT].name)
            fputs("\nCheckpoints:\n" CLI_CHECKPOINT_HELP, stdout);
        if (options[OPT_POINT].name) {
            fputs("\nScene:\n" CLI_SCENE_HELP, stdout);
            fputs(CLI_LIGHT_HELP, stdout);
        }
        *exit_code = EXIT_OK;
        return false;
    }
    if (!cli_parse_shared(args, shared))
        return false;
    cli_progress_mark(); /* a phase nobody marked counts from here, never from 0 */
    *exit_code = EXIT_OK;
    return true;
}

bool cli_scene_argument(const char *command, const cli_args *args, const char **scene_path)
{
    if (args->positional_count > 1) {
        cli_error("%s: one scene at most (see 'radiosity %s --help')", command, command);
        return false;
    }
    *scene_path = args->positional_count ? args->positional[0] : NULL;
    return true;
}

bool cli_parse_image_command(const char *command, const char *usage, int argc, char **argv,
                             const cli_option *options, int option_count, cli_args *args,
                             cli_shared *shared, cli_view *view, const char **scene_path,
                             int *exit_code)
{
    if (!cli_begin(command, usage, argc, argv, options, option_count, args, shared,
                   exit_code))
        return false;
    *exit_code = EXIT_USAGE; /* until the command has read its own options */
    if (!cli_parse_view(args, view) || !cli_scene_argument(command, args, scene_path))
        return false;
    if (!shared->output) {
        cli_error("%s: no output file: give -o OUT.png, .hdr, .pfm or .exr", command);
        return false;
    }
    if (!cli_image_output_ok(shared->output))
        return false;
    return true;
}

rad_status cli_image_run_begin(cli_image_run *run, const char *scene_path,
                               const cli_view *view, rad_error *error)
{
    memset(run, 0, sizeof(*run));
    run->t0 = rad_clock_seconds();
    rad_status status = cli_load_scene(scene_path, &run->scene, error);
    run->t_load = rad_clock_seconds();
    if (status != RAD_OK)
        return status;
    run->camera = cli_view_camera(view, run->scene);
    cli_progress_mark(); /* the trace's phase starts here, after the load */
    cli_memory_release(); /* the images reserved up front are made now */
    return rad_image_create(view->width, view->height, &run->image, error);
}

rad_status cli_image_run_write(cli_image_run *run, const char *output, const cli_view *view,
                               rad_error *error)
{
    cli_progress_end();
    run->t_trace = rad_clock_seconds();
    rad_status status = rad_image_write(run->image, output, &view->write, error);
    run->t_write = rad_clock_seconds();
    return status;
}

void cli_image_run_stats(const cli_image_run *run, const cli_shared *shared,
                         uint32_t samples_per_pixel, cli_stats *stats)
{
    stats_begin(stats);
    stats_string(stats, "scene", run->scene->source);
    stats_integer(stats, "triangles", run->scene->triangle_count);
    stats_integer(stats, "width", run->image->width);
    stats_integer(stats, "height", run->image->height);
    stats_integer(stats, "samples_per_pixel", samples_per_pixel);
    stats_integer(stats, "seed", shared->seed);
    stats_integer(stats, "threads_requested", (unsigned long long)shared->threads);
}

void cli_image_run_times(const cli_image_run *run, cli_stats *stats)
{
    stats_number(stats, "seconds_load", run->t_load - run->t0);
    stats_number(stats, "seconds_trace", run->t_trace - run->t_load);
    stats_number(stats, "seconds_write", run->t_write - run->t_trace);
    stats_number(stats, "seconds_total", run->t_write - run->t0);
}

void cli_image_run_free(cli_image_run *run)
{
    rad_image_destroy(run->image);
    rad_scene_destroy(run->scene);
    memset(run, 0, sizeof(*run));
}

rad_status cli_load_scene(const char *path, rad_scene **scene, rad_error *error)
{
    return cli_load_scene_logged(path, cli_log, NULL, scene, error);
}

rad_status cli_load_scene_logged(const char *path, rad_log_fn log, void *log_user,
                                 rad_scene **scene, rad_error *error)
{
    rad_load_options load = {log, log_user};
    rad_status status = path ? rad_scene_load(path, &load, scene, error)
                             : rad_scene_cornell_box(scene, error);
    for (int k = 0; k < override_count && status == RAD_OK; k++) {
        const material_override *o = &overrides[k];
        status = rad_scene_set_material(*scene, o->name, o->is_emission ? NULL : &o->value,
                                        o->is_emission ? &o->value : NULL, error);
        if (status != RAD_OK) {
            char message[RAD_ERROR_MESSAGE_MAX];
            snprintf(message, sizeof(message), "%s", error->message);
            snprintf(error->message, sizeof(error->message), "--%s: %.900s",
                     o->is_emission ? "emit" : "albedo", message);
            rad_scene_destroy(*scene);
            *scene = NULL;
        }
    }
    if (status == RAD_OK) {
        status = cli_apply_lights(*scene, log, log_user, error);
        if (status != RAD_OK) {
            rad_scene_destroy(*scene);
            *scene = NULL;
        }
    }
    return status;
}

/* Progress. RADIOSITY_PROGRESS picks where it goes: unset (or "auto"), one line rewritten
 * in place about 10 times a second when stderr is a terminal, nothing otherwise; "lines"
 * (or "1"), also when stderr is not a terminal, as whole lines, at most one a second per
 * phase; "0", never.
 *
 * A solver may interleave phases (the hierarchical solver refines, gathers, refines
 * again), so each phase keeps its own clock: the time since the previous report (of any
 * phase), or since cli_progress_mark, is the work the current report covers, and is added
 * to the current phase. A phase's first report thus covers the work before it (a long
 * first row, the setup), so its clock, the "done in" time and the time left count all of
 * the phase's work: a clock started at the first report would have left that out and
 * promised too little time left, the bar then sitting near 100 % for what was never
 * counted. Commands mark right before each library call (cli_begin marks the start). The
 * time left is the phase's rate so far carried to 1; a phase whose fraction goes back
 * down starts that estimate again; below 1 % (too little to go on) and at 99 % or more (a
 * guessed fraction's cap) no estimate is shown. */
enum { PROGRESS_UNKNOWN = -1, PROGRESS_OFF, PROGRESS_TERMINAL, PROGRESS_LINES };
#define PROGRESS_PHASES 8

typedef struct phase_clock {
    char name[32];
    double seconds;       /* all the phase's time so far */
    double since_restart; /* its time since its fraction last went down */
    double fraction;
    double printed;       /* when its line was last printed */
    bool done;            /* its closing line is out */
} phase_clock;

static struct {
    int mode;
    bool line_open;
    double last_report; /* 0: no report yet (and no mark) */
    phase_clock *current;
    phase_clock phases[PROGRESS_PHASES];
    unsigned count;
} progress = {PROGRESS_UNKNOWN, false, 0, NULL, {{"", 0, 0, 0, 0, false}}, 0};

static int progress_mode(void)
{
    if (progress.mode == PROGRESS_UNKNOWN) {
        const char *setting = getenv("RADIOSITY_PROGRESS");
        if (setting && (strcmp(setting, "lines") == 0 || strcmp(setting, "1") == 0))
            progress.mode = PROGRESS_LINES;
        else if (setting && strcmp(setting, "0") == 0)
            progress.mode = PROGRESS_OFF;
        else
            progress.mode = isatty(STDERR_FILENO) ? PROGRESS_TERMINAL : PROGRESS_OFF;
    }
    return progress.mode;
}

void cli_progress_mark(void) { progress.last_report = rad_clock_seconds(); }

static phase_clock *phase_named(const char *name)
{
    for (unsigned k = 0; k < progress.count; k++)
        if (strcmp(progress.phases[k].name, name) == 0)
            return &progress.phases[k];
    /* a new phase; past the table's size the last entry is reused */
    phase_clock *clock = &progress.phases[progress.count < PROGRESS_PHASES
                                              ? progress.count++
                                              : PROGRESS_PHASES - 1];
    memset(clock, 0, sizeof(*clock));
    snprintf(clock->name, sizeof(clock->name), "%s", name);
    return clock;
}

/* "4.2 s", "42 s", "3 min 5 s", "2 h 10 min" */
static void format_duration(double seconds, char *text, size_t size)
{
    if (seconds < 9.95)
        snprintf(text, size, "%.1f s", seconds);
    else if (seconds < 99.5)
        snprintf(text, size, "%.0f s", seconds);
    else if (seconds < 5999.5)
        snprintf(text, size, "%.0f min %.0f s", floor(seconds / 60), floor(fmod(seconds, 60)));
    else
        snprintf(text, size, "%.0f h %.0f min", floor(seconds / 3600),
                 fmod(floor(seconds / 60), 60));
}

void cli_progress(void *user, const char *phase, double fraction)
{
    (void)user;
    int mode = progress_mode();
    if (mode == PROGRESS_OFF)
        return;
    double now = rad_clock_seconds();
    double work = progress.last_report > 0 ? now - progress.last_report : 0;
    progress.last_report = now;
    phase_clock *clock = phase_named(phase);
    if (clock->done) {
        if (fraction >= 1)
            return; /* this phase's closing line is already out */
        /* the same phase run again (a second render): a new clock */
        clock->seconds = clock->since_restart = clock->fraction = clock->printed = 0;
        clock->done = false;
    }
    clock->seconds += work;
    if (fraction < clock->fraction)
        clock->since_restart = 0;
    clock->since_restart += work;
    clock->fraction = fraction;
    bool switched = progress.current != clock;
    progress.current = clock;
    double interval = mode == PROGRESS_LINES ? 1.0 : 0.1;
    if (fraction < 1 && !switched && now - clock->printed < interval)
        return;
    clock->printed = now;

    char text[128], elapsed[32], left[32];
    format_duration(clock->seconds, elapsed, sizeof(elapsed));
    if (fraction >= 1) {
        snprintf(text, sizeof(text), "%-14s done in %.2f s", phase, clock->seconds);
        clock->done = true;
    } else if (fraction >= 0.01 && fraction < 0.99 && clock->since_restart > 0) {
        format_duration(clock->since_restart * (1 - fraction) / fraction, left, sizeof(left));
        snprintf(text, sizeof(text), "%-14s %5.1f%%  %s, about %s left", phase,
                 100 * fraction, elapsed, left);
    } else {
        snprintf(text, sizeof(text), "%-14s %5.1f%%  %s", phase, 100 * fraction, elapsed);
    }
    if (mode == PROGRESS_LINES) {
        fprintf(stderr, "radiosity: progress: %s\n", text);
        return;
    }
    fprintf(stderr, "\r%-60s", text);
    progress.line_open = true;
    if (fraction >= 1)
        cli_progress_end();
}

void cli_progress_end(void)
{
    if (progress.line_open) {
        fputc('\n', stderr);
        progress.line_open = false;
    }
}

void stats_begin(cli_stats *stats)
{
    stats->length = (size_t)snprintf(stats->text, sizeof(stats->text), "{\n");
}

static void stats_key(cli_stats *stats, const char *key)
{
    if (stats->length >= sizeof(stats->text))
        return;
    stats->length += (size_t)snprintf(stats->text + stats->length,
                                      sizeof(stats->text) - stats->length, "%s  \"%s\": ",
                                      stats->length > 2 ? ",\n" : "", key);
}

static void stats_append(cli_stats *stats, const char *format, ...)
    __attribute__((format(printf, 2, 3)));
static void stats_append(cli_stats *stats, const char *format, ...)
{
    if (stats->length >= sizeof(stats->text))
        return;
    va_list args;
    va_start(args, format);
    stats->length += (size_t)vsnprintf(stats->text + stats->length,
                                       sizeof(stats->text) - stats->length, format, args);
    va_end(args);
}

void stats_number(cli_stats *stats, const char *key, double value)
{
    stats_key(stats, key);
    if (isfinite(value))
        stats_append(stats, "%.9g", value);
    else
        stats_append(stats, "null");
}

void stats_integer(cli_stats *stats, const char *key, unsigned long long value)
{
    stats_key(stats, key);
    stats_append(stats, "%llu", value);
}

void stats_bool(cli_stats *stats, const char *key, bool value)
{
    stats_key(stats, key);
    stats_append(stats, "%s", value ? "true" : "false");
}

void stats_string(cli_stats *stats, const char *key, const char *value)
{
    stats_key(stats, key);
    stats_append(stats, "\"");
    for (; *value; value++) {
        unsigned char c = (unsigned char)*value;
        if (c == '"' || c == '\\')
            stats_append(stats, "\\%c", c);
        else if (c < 0x20)
            stats_append(stats, "\\u%04x", c);
        else
            stats_append(stats, "%c", c);
    }
    stats_append(stats, "\"");
}

bool cli_summary_wanted(void) { return !quiet; }

static void vsummary(const char *format, va_list args) __attribute__((format(printf, 1, 0)));
static void vsummary(const char *format, va_list args)
{
    if (quiet)
        return;
    cli_progress_end();
    fputs("radiosity: ", stderr);
    vfprintf(stderr, format, args);
    fputc('\n', stderr);
}

void cli_summary(const char *format, ...)
{
    va_list args;
    va_start(args, format);
    vsummary(format, args);
    va_end(args);
}

int cli_finish(cli_stats *stats, const char *stats_path, const char *summary_format, ...)
{
    if (stats_path) {
        stats_integer(stats, "peak_memory_bytes", rad_peak_memory_bytes());
        if (rad_memory_budget()) {
            stats_integer(stats, "memory_budget_bytes", rad_memory_budget());
            stats_integer(stats, "memory_budget_peak_bytes", rad_memory_budget_peak());
        }
        if (!stats_write(stats, stats_path))
            return EXIT_ERROR;
    }
    if (summary_format) {
        va_list args;
        va_start(args, summary_format);
        vsummary(summary_format, args);
        va_end(args);
    }
    return EXIT_OK;
}

bool stats_write(cli_stats *stats, const char *path)
{
    stats_append(stats, "\n}\n");
    if (stats->length >= sizeof(stats->text)) {
        cli_error("%s: statistics too long", path);
        return false;
    }
    rad_error error;
    if (rad_write_file_atomic(path, stats->text, stats->length, &error) != RAD_OK) {
        cli_error("%s", error.message);
        return false;
    }
    return true;
}

/* The folder of `path` into folder[size] and its last component. */
static const char *split_path(const char *path, char *folder, size_t size)
{
    const char *slash = strrchr(path, '/');
    if (!slash)
        snprintf(folder, size, ".");
    else if (slash == path)
        snprintf(folder, size, "/");
    else
        snprintf(folder, size, "%.*s", (int)(slash - path), path);
    return slash ? slash + 1 : path;
}

/* The folder of path must exist, be a folder and be writable, and path must not be a
 * folder: checked before hours of work. (Root writes into a read-only folder: access()
 * says so.) */
bool cli_output_writable(const char *path)
{
    struct stat st;
    if (!*path) {
        cli_error("an output path is empty");
        return false;
    }
    if (stat(path, &st) == 0 && S_ISDIR(st.st_mode)) {
        cli_error("%s: cannot write: it is a folder", path);
        return false;
    }
    char folder[4096];
    split_path(path, folder, sizeof(folder));
    if (stat(folder, &st) != 0) {
        cli_error("%s: cannot write: folder '%s' does not exist", path, folder);
        return false;
    }
    if (!S_ISDIR(st.st_mode)) {
        cli_error("%s: cannot write: '%s' is not a folder", path, folder);
        return false;
    }
    if (access(folder, W_OK | X_OK) != 0) {
        cli_error("%s: cannot write: folder '%s' is not writable (%s)", path, folder,
                  strerror(errno));
        return false;
    }
    return true;
}

bool cli_same_output(const char *a, const char *b)
{
    if (strcmp(a, b) == 0)
        return true;
    struct stat sa, sb;
    if (stat(a, &sa) == 0 && stat(b, &sb) == 0)
        return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
    char folder_a[4096], folder_b[4096];
    const char *name_a = split_path(a, folder_a, sizeof(folder_a));
    const char *name_b = split_path(b, folder_b, sizeof(folder_b));
    return strcmp(name_a, name_b) == 0 && stat(folder_a, &sa) == 0 && stat(folder_b, &sb) == 0 &&
           sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
}

bool cli_outputs_writable(const char *const *paths, int count)
{
    for (int k = 0; k < count; k++)
        if (paths[k] && !cli_output_writable(paths[k]))
            return false;
    for (int k = 0; k < count; k++)
        for (int m = k + 1; m < count; m++)
            if (paths[k] && paths[m] && cli_same_output(paths[k], paths[m])) {
                cli_error("%s and %s: two outputs name one file", paths[k], paths[m]);
                return false;
            }
    return true;
}
