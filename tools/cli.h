/*
 * cli.h - shared pieces of the radiosity command-line tool: argument parsing, messages,
 * progress on a terminal, and the --stats report. The tool is a thin client of the
 * library's public API (include/radiosity.h); nothing here computes light.
 */
#ifndef RAD_TOOLS_CLI_H
#define RAD_TOOLS_CLI_H

#include <stdbool.h>
#include <stdio.h>

#include "radiosity.h"

/* The library's allocation functions (src/core/alloc.h: zeroed, overflow-checked, NULL on
 * failure, released with free()), so that the tool's own allocations pass the same
 * failure hook as the library's. */
void *rad_alloc_array(size_t count, size_t size);
void *rad_resize_array(void *array, size_t count, size_t size);

/* EXIT_INTERRUPTED (128 + SIGINT, what a shell reports for a run ended by Ctrl-C): a
 * hierarchical solve was stopped by Ctrl-C, and the outputs were written, complete, with
 * the solution so far. */
enum { EXIT_OK = 0, EXIT_ERROR = 1, EXIT_USAGE = 2, EXIT_INTERRUPTED = 130 };

/* An option the parser accepts: name without dashes, short letter or 0, and whether it
 * takes a value. */
typedef struct cli_option {
    const char *name;
    char short_name;
    bool takes_value;
} cli_option;

enum { CLI_MAX_GIVEN = 1024 };

/* A parsed command line: the values by option index (the last one given), every option
 * value in command-line order (for options that may repeat: read them with
 * cli_next_value), and positional arguments. */
typedef struct cli_args {
    const char *value[64]; /* NULL = not given; "" for a flag given */
    const char *positional[256]; /* viewfactors takes a list of mesh files */
    int positional_count;
    const char *given_value[CLI_MAX_GIVEN];
    int given_option[CLI_MAX_GIVEN];
    int given_count;
} cli_args;

/* Parses argv against options; on a usage error prints "radiosity: ..." plus a hint to
 * run `radiosity COMMAND --help` and returns false. */
bool cli_parse(const char *command, int argc, char **argv, const cli_option *options,
               int option_count, cli_args *args);

/* A repeatable option's values, in command-line order: start with *cursor = 0; each call
 * returns the next value of `option`, NULL after the last. */
const char *cli_next_value(const cli_args *args, int option, int *cursor);

/* How many times `option` was given. */
int cli_value_count(const cli_args *args, int option);

/* Option groups shared by several commands, at fixed indices in every command's table:
 * BASE (every command), FORMFACTOR (render, solve, viewfactors), VIEW (commands that make
 * an image), SOLVE (render, solve), SCENE (every command that loads a scene: --emit and
 * --albedo, applied by cli_load_scene). A command's own options start at OPT_OWN. Entries
 * of a group a command does not include stay empty (NULL name) and are never matched. */
enum {
    OPT_OUTPUT, OPT_THREADS, OPT_SEED, OPT_STATS, OPT_QUIET, OPT_HELP, /* BASE */
    OPT_PATCH_SIZE, OPT_VISIBILITY_RAYS, OPT_QUADRATURE, OPT_SHADOW_LEVELS, /* FORMFACTOR */
    OPT_PROXIMITY_LEVELS,
    OPT_EYE, OPT_TARGET, OPT_UP, OPT_FOV, OPT_SIZE, OPT_SPP, OPT_EXPOSURE, /* VIEW */
    OPT_EXR_FLOAT,
    OPT_SOLVER, OPT_TOLERANCE, OPT_MAX_ITERATIONS, OPT_SOLUTION,        /* SOLVE */
    OPT_SAVE_SOLUTION, OPT_REFINE_THRESHOLD, OPT_MAX_MEMORY, OPT_PLOT, OPT_RECORD,
    OPT_SOLVE_CHECKPOINT, OPT_SOLVE_CHECKPOINT_INTERVAL, OPT_SOLVE_RESUME,
    OPT_EMIT, OPT_ALBEDO,                                               /* SCENE */
    OPT_POINT, OPT_SPOT, OPT_SUN, OPT_TIME, OPT_SKY, OPT_LUMINAIRE, OPT_ENVIRONMENT,
    OPT_ENVIRONMENT_ROTATE, OPT_UNIT, OPT_NORTH,
    OPT_OWN
};

#define CLI_BASE_OPTIONS                                                                   \
    [OPT_OUTPUT] = {"output", 'o', true}, [OPT_THREADS] = {"threads", 0, true},            \
    [OPT_SEED] = {"seed", 0, true}, [OPT_STATS] = {"stats", 0, true},                      \
    [OPT_QUIET] = {"quiet", 0, false}, [OPT_HELP] = {"help", 'h', false}

/* The help lines of the BASE group; `stats` says what the --stats file holds. */
#define CLI_BASE_HELP(stats)                                                               \
    "  --threads N          worker threads (default: all cores)\n"                           \
    "  --seed N             seed of every random choice (default " CLI_STR(CLI_DEFAULT_SEED) ")\n" \
    "  --stats FILE.json    write " stats "\n" CLI_QUIET_HELP

/* The help lines of --quiet and --help (every command). */
#define CLI_QUIET_HELP                                                                     \
    "  --quiet              no summary line at the end of the run (warnings still show)\n"   \
    "  -h, --help           this text\n"

/* A constant's value as text, for help texts: CLI_STR(RAD_DEFAULT_MAX_DEPTH) is "5". */
#define CLI_STR(x) CLI_STR_(x)
#define CLI_STR_(x) #x

/* The seed when --seed is not given. */
#define CLI_DEFAULT_SEED 1

/* The image size when --size is not given. */
#define CLI_DEFAULT_WIDTH 512
#define CLI_DEFAULT_HEIGHT 512

#define CLI_FORMFACTOR_OPTIONS                                                             \
    [OPT_PATCH_SIZE] = {"patch-size", 0, true},                                            \
    [OPT_VISIBILITY_RAYS] = {"visibility-rays", 0, true},                                  \
    [OPT_QUADRATURE] = {"quadrature", 0, true},                                            \
    [OPT_SHADOW_LEVELS] = {"shadow-levels", 0, true},                                      \
    [OPT_PROXIMITY_LEVELS] = {"proximity-levels", 0, true}

#define CLI_VIEW_OPTIONS                                                                   \
    [OPT_EYE] = {"eye", 0, true}, [OPT_TARGET] = {"target", 0, true},                      \
    [OPT_UP] = {"up", 0, true}, [OPT_FOV] = {"fov", 0, true},                              \
    [OPT_SIZE] = {"size", 0, true}, [OPT_SPP] = {"spp", 0, true},                          \
    [OPT_EXPOSURE] = {"exposure", 0, true}, [OPT_EXR_FLOAT] = {"exr-float", 0, false}

#define CLI_SOLVE_OPTIONS                                                                  \
    [OPT_SOLVER] = {"solver", 0, true}, [OPT_TOLERANCE] = {"tolerance", 0, true},          \
    [OPT_MAX_ITERATIONS] = {"max-iterations", 0, true},                                    \
    [OPT_SOLUTION] = {"solution", 0, true}, [OPT_SAVE_SOLUTION] = {"save-solution", 0, true}, \
    [OPT_REFINE_THRESHOLD] = {"refine-threshold", 0, true},                                \
    [OPT_MAX_MEMORY] = {"max-memory", 0, true}, [OPT_PLOT] = {"plot", 0, true},             \
    [OPT_RECORD] = {"record", 0, true},                                                    \
    [OPT_SOLVE_CHECKPOINT] = {"checkpoint", 0, true},                                      \
    [OPT_SOLVE_CHECKPOINT_INTERVAL] = {"checkpoint-interval", 0, true},                    \
    [OPT_SOLVE_RESUME] = {"resume", 0, true}

/* The help of the options `render` and `solve` share (SOLVE, FORMFACTOR, SCENE, BASE but
 * -o), the same for both: a solution file of one is a solution file of the other. */
/* Printed after the command's usage by every command that meshes a scene. */
#define CLI_MESH_HELP                                                                      \
    "  --shadow-levels N    split a patch that a light's shadow edge or an emitter's\n"   \
    "                       penumbra crosses into four, and its children again, N times\n" \
    "                       (default " CLI_STR(RAD_SHADOW_LEVELS_DEFAULT) ", at most "        \
    CLI_STR(RAD_SHADOW_LEVELS_MAX) ", 0 = none)\n"                                          \
    "  --proximity-levels N split a patch larger than 1/3 of the mean distance to the\n"   \
    "                       surfaces it sees into four, and its children again, N times\n" \
    "                       (at most " CLI_STR(RAD_PROXIMITY_LEVELS_MAX) ", 0 = none; default "  \
    CLI_STR(RAD_PROXIMITY_LEVELS_DEFAULT) " with the dense solvers' automatic patch\n"       \
    "                       size, 0 with --patch-size or --solver hierarchical): rooms\n"  \
    "                       get patches of their own size\n"

#define CLI_SOLVE_HELP                                                                     \
    "Solution:\n"                                                                          \
    "  --solution FILE      take the solution saved in FILE (by --save-solution) instead\n" \
    "                       of solving; refused if FILE belongs to another scene (--emit,\n" \
    "                       --albedo) or meshing; the solver options are then ignored\n"   \
    "  --save-solution FILE also write the solution to FILE, for later --solution runs\n"  \
    "  --solver NAME        gather (Jacobi), gauss-seidel, shoot, direct (LU, small\n"       \
    "                       scenes only), or hierarchical (links between element and\n"     \
    "                       cluster trees, no n x n matrix: large scenes). Default: the\n"  \
    "                       library's choice: gather up to " CLI_STR(RAD_DENSE_MAX_PATCHES)   \
    " patches, else\n"                                                                     \
    "                       hierarchical (the summary and --stats say which ran)\n"         \
    "  --refine-threshold X hierarchical: split a link while B x F x A exceeds X times\n"   \
    "                       the emitted power per patch (default "                     \
    CLI_STR(RAD_DEFAULT_REFINE_THRESHOLD) "; auto " CLI_STR(RAD_AUTO_REFINE_THRESHOLD)       \
    " to " CLI_STR(RAD_AUTO_FINE_LINKS_PATCHES) " patches)\n"                              \
    "  --max-memory SIZE    bytes the whole run may hold (K, M, G): known sizes (image,\n" \
    "                       matrix 4 n^2, trees) refused up front, links stop there,\n"    \
    "                       the rest an error (default: none; links: half of RAM)\n"       \
    "  --tolerance X        relative residual, or unshot fraction for shoot, or change of\n" \
    "                       a sweep for hierarchical (default "                            \
    CLI_STR(RAD_DEFAULT_TOLERANCE) ")\n"                                                   \
    "  --max-iterations N   sweeps, or shots for shoot (default "                          \
    CLI_STR(RAD_DEFAULT_MAX_SWEEPS) " sweeps,\n"                                           \
    "                       " CLI_STR(RAD_DEFAULT_SHOTS_PER_PATCH) " n shots for n patches, " \
    CLI_STR(RAD_DEFAULT_HIERARCHY_SWEEPS) " sweeps for hierarchical)\n"                    \
    "  --patch-size L       longest patch edge in scene units (default: about "            \
    CLI_STR(RAD_DEFAULT_PATCHES) "\n"                                                      \
    "                       patches, " CLI_STR(RAD_HIERARCHICAL_DEFAULT_PATCHES)              \
    " with --solver hierarchical, or the one\n"                                            \
    "                       --solution's file was solved with)\n"                           \
    "  --visibility-rays N  most occlusion rays per patch pair (default "                  \
    CLI_STR(RAD_DEFAULT_VISIBILITY_RAYS) ") or link ("                                     \
    CLI_STR(RAD_DEFAULT_LINK_VISIBILITY_RAYS) ":\n"                                        \
    "                       4 first, all N unless all 4 are open)\n"                       \
    "  --quadrature M       M x M points per patch for the analytic form factor (default " \
    CLI_STR(RAD_DEFAULT_QUADRATURE) ")\n"                                                 \
    "  --threads N          worker threads (default: all cores)\n"                          \
    "  --seed N             seed of every random choice (default 1)\n"                      \
    "  --stats FILE.json    write counts, times, residuals and peak memory\n"               \
    "  --quiet              no summary line at the end (warnings and errors still show)\n"  \
    "  -h, --help           this text\n"                                                    \
    "\n" CLI_INTERRUPT_HELP

/* The help of --plot and --record (SOLVE group), printed after the command's own. */
#define CLI_CONVERGENCE_HELP                                                               \
    "  --plot FILE.svg      the convergence plot: residual (and unshot energy or change of\n" \
    "                       a sweep) against iterations and against time, log scale\n"    \
    "  --record FILE.json   the solution at every step (sweeps; shooting: every n/16\n"    \
    "                       shots; hierarchical: sweeps and refinement passes) with its\n" \
    "                       residual, as JSON (radiosity: base64 float32 RGB per patch)\n"

/* The help of --checkpoint, --checkpoint-interval and --resume (SOLVE group), printed
 * after the command's own. */
#define CLI_CHECKPOINT_HELP                                                                \
    "  --checkpoint FILE    write the solve's state to FILE (atomically) every\n"          \
    "                       --checkpoint-interval seconds: dense solvers the form-factor\n" \
    "                       rows done, then the iterate; hierarchical the links and B;\n"  \
    "                       SIGINT or SIGTERM (Ctrl-C) then stop any solver at its next\n" \
    "                       step, write one and end the run (status 130, no output file)\n" \
    "  --checkpoint-interval S  seconds between checkpoints (default "                     \
    CLI_STR(CLI_CHECKPOINT_INTERVAL) "; 0: at every\n"                                    \
    "                       step: a round of rows, a sweep, n/16 shots)\n"                 \
    "  --resume FILE        continue the solve of this checkpoint (same scene, mesh,\n"    \
    "                       --solver and solver options; others are refused): the\n"      \
    "                       outputs are those of an uninterrupted run. Checkpoints go on\n" \
    "                       to FILE unless --checkpoint names another\n"

/* What Ctrl-C does, for the help of every command that solves. */
#define CLI_INTERRUPT_HELP                                                                 \
    "Ctrl-C during a hierarchical solve stops refinement and gathering at the end of the\n"  \
    "current pass or sweep and the run goes on with the solution so far (written by\n"      \
    "--save-solution, rendered or written as a lit mesh, each file complete), then exits\n"  \
    "with status 130; a second Ctrl-C ends the run at once. Progress (each phase, its time\n" \
    "and the time left) shows on a terminal; RADIOSITY_PROGRESS=lines prints it as lines\n"  \
    "elsewhere too, RADIOSITY_PROGRESS=0 never.\n"

#define CLI_SCENE_OPTIONS                                                                  \
    [OPT_EMIT] = {"emit", 0, true}, [OPT_ALBEDO] = {"albedo", 0, true},                    \
    [OPT_POINT] = {"point", 0, true}, [OPT_SPOT] = {"spot", 0, true},                      \
    [OPT_SUN] = {"sun", 0, true}, [OPT_TIME] = {"time", 0, true},                          \
    [OPT_SKY] = {"sky", 0, true}, [OPT_LUMINAIRE] = {"luminaire", 0, true},                \
    [OPT_ENVIRONMENT] = {"environment", 0, true},                                          \
    [OPT_ENVIRONMENT_ROTATE] = {"environment-rotate", 0, true},                            \
    [OPT_UNIT] = {"unit", 0, true}, [OPT_NORTH] = {"north", 0, true}

/* The help of the SCENE group's options, --emit and --albedo (CLI_SCENE_HELP) and the
 * light sources (CLI_LIGHT_HELP), printed after a command's own help when its table has
 * the group (the texts would not fit in one string literal with a command's own). */
#define CLI_LIGHT_HELP                                                                     \
    "\n"                                                                                   \
    "Light sources besides emissive surfaces (repeatable; in candela and lux, radiance\n"    \
    "comes out as luminance in cd/m^2 and irradiance as illuminance in lux):\n"            \
    "  --point X,Y,Z:CD[:R,G,B]          a point light of CD candela (times R,G,B)\n"      \
    "  --spot X,Y,Z:DX,DY,DZ:CD:IN:OUT[:R,G,B]  a spot along DX,DY,DZ: CD inside IN\n"     \
    "                       degrees of its axis, none past OUT (half-angles), glTF falloff\n" \
    "  --sun X,Y,Z[:LUX[:DIAM]]          the sun toward X,Y,Z: LUX on a plane facing it\n" \
    "                       (default 100000), a disk DIAM degrees across (default 0.53)\n" \
    "  --sun LAT,LON[:LUX[:DIAM]] --time YYYY-MM-DDTHH:MM[+HH:MM]  the sun's place at\n"    \
    "                       that local time (NOAA's algorithm); below the horizon: none\n"  \
    "  --sky uniform|cie-overcast|cie-clear[:LZ]  a sky of zenith luminance LZ cd/m^2\n"    \
    "                       (default: 10000 lux on open ground); cie-clear needs --sun\n"   \
    "  --luminaire FILE.ies:X,Y,Z[:AX,AY,AZ[:FACTOR]]  an IES LM-63 photometric web at\n" \
    "                       X,Y,Z, its nadir along AX,AY,AZ (default: down), times FACTOR\n" \
    "  --environment FILE[:SCALE]  an equirectangular radiance map (.hdr, .exr, .pfm; 2:1,\n" \
    "                       its centre looking north, top the zenith) around the scene\n"   \
    "  --environment-rotate DEG  turn it about the up axis (clockwise from above)\n"      \
    "  --unit m|cm|mm|in|ft  the scene's length unit, for the inverse-square law (default:\n" \
    "                       the file's, glTF metres; else metres)\n"                        \
    "  --north X,Y,Z        the scene's north (default -z for y up, +y for z up)\n"

/* The help lines of the SCENE group. */
#define CLI_SCENE_HELP                                                                     \
    "  --emit NAME=R,G,B    set the emitted radiance of surface NAME, else of every\n"       \
    "                       material NAME (exact, else ignoring case); repeatable\n"        \
    "  --albedo NAME=R,G,B  set its albedo (0 to 1) the same way; repeatable\n"

/* --two-sided NAME (render, solve, raytrace, pathtrace; repeatable): the names given, in
 * order, applied to the scene after loading (cli_apply_two_sided, cli_solve.c). */
typedef struct cli_two_sided {
    const char *name[CLI_MAX_GIVEN];
    int count;
} cli_two_sided;

#define CLI_TWO_SIDED_HELP                                                                 \
    "  --two-sided NAME     surface or material NAME radiates on both sides; repeatable\n"

/* The values of `option` (the command's --two-sided) in *out. */
void cli_parse_two_sided(const cli_args *args, int option, cli_two_sided *out);

/* Sets RAD_SURFACE_TWO_SIDED on what each name names (rad_scene_set_surface_flags); an
 * unknown name is an error "--two-sided: ..." naming it. */
rad_status cli_apply_two_sided(const cli_two_sided *two_sided, rad_scene *scene,
                               rad_error *error);

/* What the BASE and FORMFACTOR options say; patch_size 0 = the command's default. */
typedef struct cli_shared {
    const char *output, *stats_path;
    double patch_size;
    int shadow_levels; /* rad_mesh_options.shadow_levels: 0 default, -1 none */
    int proximity_levels; /* rad_mesh_options.proximity_levels: 0 default, -1 none */
    rad_formfactor_options formfactor; /* quadrature, visibility rays, threads, seed, progress */
    int threads;
    unsigned long seed;
} cli_shared;

/* Parses the BASE, FORMFACTOR and SCENE options (after cli_parse); false (after printing)
 * on a bad value. The SCENE options are kept for cli_load_scene, --quiet for cli_summary. */
bool cli_parse_shared(const cli_args *args, cli_shared *shared);

/* The opening every command shares: parses argv against its option table, prints `usage`
 * for --help, and reads the BASE, FORMFACTOR and SCENE groups (cli_parse_shared). Returns
 * false with *exit_code set (EXIT_OK after --help, EXIT_USAGE on a usage error) when the
 * command should stop. */
bool cli_begin(const char *command, const char *usage, int argc, char **argv,
               const cli_option *options, int option_count, cli_args *args,
               cli_shared *shared, int *exit_code);

/* The optional SCENE argument: *scene_path is it, or NULL when none is given; false after
 * a usage error when there are more. */
bool cli_scene_argument(const char *command, const cli_args *args, const char **scene_path);

/* The help lines of the VIEW group: the camera (a heading and one line), and the
 * image file's options. */
#define CLI_CAMERA_HELP                                                                    \
    "Camera (default: the scene's camera, or a view of the whole scene from -z):\n"         \
    "  --eye X,Y,Z  --target X,Y,Z  --up X,Y,Z  --fov DEG (vertical)   --size WxH ("          \
    CLI_STR(CLI_DEFAULT_WIDTH) "x" CLI_STR(CLI_DEFAULT_HEIGHT) ")\n"
#define CLI_IMAGE_FILE_HELP                                                                \
    "  --exposure EV        PNG: scale radiance by 2^EV (default: automatic)\n"              \
    "  --exr-float          .exr: 32-bit float channels instead of half\n"

/* Sets the seed, threads and progress fields every library options struct has from the
 * BASE options. */
#define CLI_SET_RUN_OPTIONS(options, shared)                                               \
    ((options).seed = (shared).seed, (options).threads = (shared).threads,                  \
     (options).progress = cli_progress)

/* What the VIEW options say. */
typedef struct cli_view {
    rad_camera camera;                 /* fields given on the command line */
    bool has_eye, has_target, has_up, has_fov;
    uint32_t width, height;            /* CLI_DEFAULT_WIDTH x CLI_DEFAULT_HEIGHT by default */
    uint32_t samples_per_pixel;        /* 0 = the library's default */
    rad_image_write_options write;     /* exposure, --exr-float */
} cli_view;

bool cli_parse_view(const cli_args *args, cli_view *view);

/* The scene's camera (or a framing default) with the command line's overrides. */
rad_camera cli_view_camera(const cli_view *view, const rad_scene *scene);

/* Parses a byte count with an optional K, M or G suffix (powers of 1024), at least 1;
 * prints "--NAME: 'TEXT' is not a size in bytes ..." otherwise. */
bool cli_parse_bytes(const char *name, const char *text, uint64_t *out);

/* The bytes `images` images of the view's size hold (12 a pixel each), and, written to
 * `path` as a PNG with automatic exposure, the luminance it sorts (8 a pixel): what
 * --max-memory must hold for them from the start. */
uint64_t cli_image_bytes(const cli_view *view, const char *path, int images);

/* --max-memory SIZE (0 = not given): the whole run's memory budget (rad_memory_budget_set),
 * set before anything is loaded. */
void cli_memory_budget(uint64_t bytes);

/* Up front: `need` bytes for `what`, made later ("the 512 x 512 image"), are reserved out
 * of the budget (rad_memory_budget_reserve); false, after printing the line "--max-memory:
 * WHAT needs X, more than the Y left of the budget of Z", when they do not fit. True at
 * once without a budget. */
bool cli_memory_take(uint64_t need, const char *what);

/* Gives back what cli_memory_take reserved, just before those buffers are made. */
void cli_memory_release(void);

/* True for .png, .hdr and .pfm; prints the usage error otherwise. */
bool cli_image_output_ok(const char *path);

/* cli_begin for the image commands: also reads the VIEW group, the optional SCENE and the
 * required -o OUT image. On success *exit_code is EXIT_USAGE, for the command's own
 * checks that follow (it sets EXIT_OK when they pass). */
bool cli_parse_image_command(const char *command, const char *usage, int argc, char **argv,
                             const cli_option *options, int option_count, cli_args *args,
                             cli_shared *shared, cli_view *view, const char **scene_path,
                             int *exit_code);

/* Loads SCENE, or the built-in Cornell box when path is NULL, and applies the --emit and
 * --albedo options cli_parse_shared saw, in command-line order; warnings go to stderr, an
 * unknown NAME is an error naming it. */
rad_status cli_load_scene(const char *path, rad_scene **scene, rad_error *error);

/* The same with the loader's warnings sent to `log` instead. */
rad_status cli_load_scene_logged(const char *path, rad_log_fn log, void *log_user,
                                 rad_scene **scene, rad_error *error);

/* The light-source options (cli_lights.c): checked with the shared options (false after
 * printing what is wrong), then added to a loaded scene by cli_load_scene. */
bool cli_parse_lights(const cli_args *args);
rad_status cli_apply_lights(rad_scene *scene, rad_log_fn log, void *log_user,
                            rad_error *error);

/* Value parsers: print "radiosity: --NAME: ..." and return false on a bad value. */
bool cli_parse_double(const char *name, const char *text, double *out);
bool cli_parse_positive(const char *name, const char *text, double *out); /* > 0 */
bool cli_parse_uint(const char *name, const char *text, unsigned long max, unsigned long *out);
/* A count from min to max into *out; text NULL (the option not given) leaves *out as it is. */
bool cli_parse_count(const char *name, const char *text, uint32_t min, uint32_t max,
                     uint32_t *out);
bool cli_parse_vec3(const char *name, const char *text, rad_vec3 *out);
bool cli_parse_size(const char *name, const char *text, uint32_t *width, uint32_t *height);

void cli_error(const char *format, ...) __attribute__((format(printf, 1, 2)));
void cli_warn(const char *format, ...) __attribute__((format(printf, 1, 2)));
/* A rad_log_fn printing "radiosity: warning: message". */
void cli_log(void *user, const char *message);

/* Progress on stderr (user: NULL): on a terminal, or as whole lines with
 * RADIOSITY_PROGRESS=lines (cli.c). Each phase shows its fraction, its time and the time
 * left. */
void cli_progress(void *user, const char *phase, double fraction);
void cli_progress_end(void);
/* The work from now on belongs to the next phase reported (its first report then counts
 * the time since here). */
void cli_progress_mark(void);

/* The run's last line on stderr, "radiosity: " + the formatted text, printed on every run
 * (terminal or not) unless --quiet was given: what was computed (patches, elements,
 * samples), the time, the residual, what was written. */
void cli_summary(const char *format, ...) __attribute__((format(printf, 1, 2)));
/* False after --quiet. */
bool cli_summary_wanted(void);

/* The --stats report: a flat JSON object built up field by field. */
typedef struct cli_stats {
    char text[8192];
    size_t length;
} cli_stats;

void stats_begin(cli_stats *stats);
void stats_number(cli_stats *stats, const char *key, double value);
void stats_integer(cli_stats *stats, const char *key, unsigned long long value);
void stats_string(cli_stats *stats, const char *key, const char *value);
void stats_bool(cli_stats *stats, const char *key, bool value);
/* Closes the object and writes it atomically; false (after printing) on failure. */
bool stats_write(cli_stats *stats, const char *path);

/* How every command ends: with stats_path, adds peak_memory_bytes and writes the --stats
 * file (stats_write); then, unless that failed, the summary line (cli_summary; none when
 * summary_format is NULL). Returns the exit code: EXIT_OK, or EXIT_ERROR (after printing)
 * when the stats file failed. */
int cli_finish(cli_stats *stats, const char *stats_path, const char *summary_format, ...)
    __attribute__((format(printf, 3, 4)));

/* Prints error's message (a run that failed) and returns EXIT_ERROR. */
int cli_failed(const rad_error *error);

/* What the image commands (raytrace, pathtrace) do around their one library call: load
 * the scene, frame it, make the image, write it, and report. */
typedef struct cli_image_run {
    rad_scene *scene;
    rad_camera camera; /* cli_view_camera */
    rad_image *image;  /* view->width x view->height */
    double t0, t_load, t_trace, t_write; /* rad_clock_seconds at the start and after each */
} cli_image_run;

/* Loads SCENE (cli_load_scene; NULL = the built-in Cornell box), sets the camera and
 * creates the image. The run is always freeable by cli_image_run_free. */
rad_status cli_image_run_begin(cli_image_run *run, const char *scene_path,
                               const cli_view *view, rad_error *error);
/* Writes the image to `output` with the view's write options, after the trace (whose
 * progress line it closes). */
rad_status cli_image_run_write(cli_image_run *run, const char *output, const cli_view *view,
                               rad_error *error);
/* Starts the --stats report: scene, triangles, width, height, samples_per_pixel, seed,
 * threads_requested (0 = all). */
void cli_image_run_stats(const cli_image_run *run, const cli_shared *shared,
                         uint32_t samples_per_pixel, cli_stats *stats);
/* Its times: seconds_load, seconds_trace, seconds_write, seconds_total. */
void cli_image_run_times(const cli_image_run *run, cli_stats *stats);
void cli_image_run_free(cli_image_run *run);

/* What the SOLVE options say (cli_solve.c). */
typedef struct cli_solve {
    rad_scene_solve_options options; /* solver (AUTO unless --solver), tolerance, limits,
                                        threshold, memory, rays, seed, threads, log,
                                        progress */
    const char *solution_path;      /* --solution: read B from this file instead of solving */
    const char *save_solution_path; /* --save-solution: write B to this file */
    cli_two_sided two_sided;        /* --two-sided, set by the command after cli_parse_solve;
                                       applied by cli_solve_scene before meshing */
    const char *plot_path;          /* --plot: the convergence plot (SVG) */
    const char *record_path;        /* --record: the snapshots (JSON) */
    const char *checkpoint_path;    /* --checkpoint (or --resume's file): NULL none */
    const char *resume_path;        /* --resume */
    double checkpoint_interval;     /* --checkpoint-interval, seconds */
    bool light_at_vertices;         /* set by the command: the light at the vertices follows
                                       the solve (render, or a lit mesh, not --direct
                                       solution); with --max-memory, cli_solve_scene checks
                                       it fits before solving */
} cli_solve;

/* Parses the SOLVE options (after cli_parse_shared, whose threads, seed, quadrature and
 * visibility rays it takes); false (after printing) on a bad value. */
bool cli_parse_solve(const cli_args *args, const cli_shared *shared, cli_solve *solve);

/* -o, --stats and --save-solution can be written (cli_output_writable each). */
bool cli_solve_outputs_writable(const cli_shared *shared, const cli_solve *solve);

/* A scene, its mesh and its solution, and what getting them cost. */
typedef struct cli_solved {
    rad_scene *scene;
    rad_mesh *mesh;
    rad_rgb *B;     /* mesh->patch_count exitances */
    rad_patch_inputs *inputs; /* built once: the solve's and the render's */
    bool from_file; /* B came from --solution: nothing solved, `report` is empty */
    rad_scene_solve_report report; /* rad_solve_scene's: the solver it chose, and all */
    double seconds_load, seconds_mesh, seconds_inputs, seconds_save;
    bool checkpoint_stop; /* stopped by a signal with --checkpoint: the checkpoint holds
                             the state, nothing else is to be written (cli_checkpoint_stop) */
} cli_solved;

/* The part `render` and `solve` share: loads SCENE (NULL = the built-in Cornell box),
 * meshes it (--patch-size, else the solution file's, else rad_default_patch_size), then
 * reads B from --solution (refused unless it belongs to this scene and mesh) or solves
 * with rad_solve_scene (Ctrl-C stops a hierarchical solve with the solution so far);
 * writes --save-solution. On failure, fills error and frees what it made. */
rad_status cli_solve_scene(const char *scene_path, const cli_shared *shared,
                           const cli_solve *solve, cli_solved *out, rad_error *error);
void cli_solved_free(cli_solved *solved);

/* After a solve stopped at a checkpoint (cli_solved.checkpoint_stop): rank 0 says where to
 * resume from; returns EXIT_INTERRUPTED. The command then writes nothing. */
int cli_checkpoint_stop(const char *command, const cli_solve *solve);

/* The --stats fields of the solution: scene, patches, rays, phase times, solver,
 * iterations, residuals and form-factor checks (or the solution file it came from). */
void cli_solved_stats(const cli_solved *solved, const cli_solve *solve, cli_stats *stats);

/* One line for a person watching a terminal: "N patches, M rays, K sweeps (residual R)". */
void cli_solved_summary(const cli_solved *solved, const cli_solve *solve, char *text,
                        size_t size);

/* --plot and --record (cli_convergence.c): an observer of the solve that keeps its steps
 * for the plot and streams its snapshots to the record. */
typedef struct cli_convergence {
    const char *plot_path;
    rad_solve_record *record;
    rad_convergence history;
    char scene[256];
    rad_solver solver;
    uint32_t patches;
    rad_status status; /* the observer's first error */
    rad_error error;
} cli_convergence;

/* False (after printing) when --plot is not a .svg name or both options name one file. */
bool cli_convergence_paths_ok(const char *plot_path, const char *record_path);

/* Opens the record (when record_path is given) and sets options->observer (when either
 * is given). */
rad_status cli_convergence_begin(cli_convergence *c, const char *plot_path,
                                 const char *record_path, const char *scene, rad_solver solver,
                                 uint32_t patches, rad_scene_solve_options *options,
                                 rad_error *error);

/* After the solve (its status `solved`): commits the record (or removes it when anything
 * failed) and writes the plot; frees what begin made. */
rad_status cli_convergence_end(cli_convergence *c, rad_status solved, rad_error *error);

/* viewfactors --plot: the fraction of polygon pairs left against time, from the
 * computation's progress reports (it has no iteration to watch). */
typedef struct cli_viewfactor_plot {
    const char *path;
    rad_convergence history;
    double start;
    rad_status status;
    rad_error error;
} cli_viewfactor_plot;

/* With a path: hooks the progress of `options` (which still reaches the terminal). */
void cli_viewfactor_plot_begin(cli_viewfactor_plot *p, const char *path,
                               rad_viewfactor_options *options);
/* Writes the plot (nothing without a path); frees the history. */
rad_status cli_viewfactor_plot_end(cli_viewfactor_plot *p, const char *scene,
                                   uint32_t surfaces, rad_error *error);

/* Seconds between checkpoints unless --checkpoint-interval says (viewfactors, solve,
 * render). */
#define CLI_CHECKPOINT_INTERVAL 600

/* What the checkpointing commands share (cli_checkpoint.c): SIGINT and SIGTERM raise the
 * stop flag (a second one ends the run at once), and "checkpoint" progress reports are
 * counted, not drawn. For tests, RADIOSITY_STOP_AFTER_CHECKPOINTS=K acts as SIGTERM once K
 * checkpoints are written, so that a run can be interrupted at a known point without
 * timing, and RADIOSITY_WAIT_AFTER_CHECKPOINTS=K waits there (up to a minute) for a real
 * SIGINT or SIGTERM, so that a test's signal always arrives mid-run. */
typedef struct cli_checkpoints {
    long stop_after, wait_after, written; /* 0: never */
    rad_progress_fn next; /* gets every other report (the progress line, --plot) */
    void *next_user;
    void (*previous_int)(int);
    void (*previous_term)(int);
} cli_checkpoints;

/* Installs the handlers and, on a rank that reports progress (*progress may be NULL),
 * wraps *progress; returns the stop flag for the library's options. */
const volatile int *cli_checkpoints_begin(cli_checkpoints *c, rad_progress_fn *progress,
                                          void **progress_user);
/* Puts the previous signal handlers back. */
void cli_checkpoints_end(cli_checkpoints *c);

/* Parses --checkpoint-interval into *seconds (false after printing for a bad value). */
bool cli_parse_checkpoint_interval(const char *value, double *seconds);

/* Prints an error and returns false when path is a folder or its folder is not writable. */
bool cli_output_writable(const char *path);

/* cli_output_writable for each of the `count` paths that is not NULL, and no two of them
 * naming one file (cli_same_output), checked before any work; false at the first that
 * fails. */
bool cli_outputs_writable(const char *const *paths, int count);

/* Whether the two output paths name one file: the same text, the same existing file, or
 * the same name in the same folder (./a.mtx and a.mtx; the folders must exist). */
bool cli_same_output(const char *a, const char *b);

/* The subcommands, one file each (cmd_NAME.c); argv holds the arguments after the
 * subcommand's name. Each returns the process exit code. */
int command_render(int argc, char **argv);
int command_solve(int argc, char **argv);
int command_viewfactors(int argc, char **argv);
int command_raytrace(int argc, char **argv);
int command_pathtrace(int argc, char **argv);
int command_compare(int argc, char **argv);
int command_info(int argc, char **argv);
int command_illuminance(int argc, char **argv);
int command_view(int argc, char **argv);
int command_plot(int argc, char **argv);

#endif
