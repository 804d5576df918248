/*
 * cmd_illuminance.c - `radiosity illuminance [SCENE] --plane HEIGHT | --points FILE -o
 * OUT.csv`: illuminance where lighting designers read it, on a work plane or at measuring
 * points, with the summary they judge a design by (E_min, E_avg, E_max, uniformity) and,
 * under a sky, the daylight factor.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

static const char usage[] =
    "usage: radiosity illuminance [SCENE] (--plane HEIGHT | --points FILE.csv) -o OUT.csv\n"
    "                             [options]\n"
    "\n"
    "Solves the radiosity of SCENE (none = the built-in Cornell box) and writes the\n"
    "illuminance (lux with lights in candela and lux; the irradiance otherwise) at\n"
    "calculation points to OUT.csv, one row per point: x,y,z,nx,ny,nz,E_r,E_g,E_b,E (E the\n"
    "luminance-weighted value), and daylight_factor_percent when a sky alone lights the\n"
    "scene (E over the sky's illuminance on open ground, in percent). The summary line\n"
    "gives E_min, E_avg, E_max and the uniformity E_min / E_avg. Direct light from point,\n"
    "spot, luminaire and sun lights is exact (shadow rays), emitters' by light samples\n"
    "and cosine rays (MIS); light from the sky and reflected by surfaces is gathered.\n"
    "\n"
    "  --plane HEIGHT       a horizontal grid HEIGHT scene units above the floor (lighting\n"
    "                       standards use 0.75 or 0.8 m), over the floor only\n"
    "  --spacing S          grid spacing (default: 0.25 m when the scene's unit is known,\n"
    "                       from the file or --unit; else 1/40 of the scene's width)\n"
    "  --points FILE.csv    measuring points instead: rows x,y,z[,nx,ny,nz] (normal\n"
    "                       default: the scene's up); lines starting with # are skipped\n"
    "  --gather-rays N      hemisphere directions per point (default "
    CLI_STR(RAD_DEFAULT_GATHER_RAYS) ")\n"
    "  -o, --output FILE    the table (.csv)\n"
    CLI_TWO_SIDED_HELP
    "The solution options are render's (radiosity render --help): --solver, --solution,\n"
    "--patch-size, --tolerance, --max-memory, --emit, --albedo, --threads, --seed, --stats.\n";

enum { OPT_PLANE = OPT_OWN, OPT_SPACING, OPT_POINTS, OPT_GATHER_RAYS, OPT_TWO_SIDED, OPT_COUNT };

static const cli_option options[OPT_COUNT] = {
    CLI_BASE_OPTIONS,
    CLI_FORMFACTOR_OPTIONS,
    CLI_SOLVE_OPTIONS,
    CLI_SCENE_OPTIONS,
    [OPT_PLANE] = {"plane", 0, true},
    [OPT_SPACING] = {"spacing", 0, true},
    [OPT_POINTS] = {"points", 0, true},
    [OPT_GATHER_RAYS] = {"gather-rays", 0, true},
    [OPT_TWO_SIDED] = {"two-sided", 0, true},
};

#define MAX_POINTS 10000000u /* in a --points file */

/* Reads measuring points: x,y,z[,nx,ny,nz] per line. */
static rad_status read_points(const char *path, rad_vec3 up, rad_vec3 **points,
                              rad_vec3 **normals, uint32_t *count, rad_error *error)
{
    *points = NULL;
    *normals = NULL;
    *count = 0;
    FILE *file = fopen(path, "r");
    if (!file) {
        snprintf(error->message, sizeof(error->message), "%s: cannot open: %s", path,
                 strerror(errno));
        return error->status = RAD_ERR_IO;
    }
    char line[1024];
    uint32_t capacity = 0, line_number = 0;
    rad_status status = RAD_OK;
    while (fgets(line, sizeof(line), file)) {
        line_number++;
        char *text = line;
        while (*text == ' ' || *text == '\t')
            text++;
        if (*text == '#' || *text == '\n' || *text == '\r' || *text == '\0')
            continue;
        if (!strchr(line, '\n') && !feof(file)) {
            snprintf(error->message, sizeof(error->message), "%s:%u: line longer than %zu bytes",
                     path, line_number, sizeof(line) - 2);
            status = error->status = RAD_ERR_PARSE;
            break;
        }
        double v[6];
        int n = 0;
        bool clean = false; /* the numbers end the line */
        char *cursor = text;
        while (n < 6) {
            char *end;
            errno = 0;
            v[n] = strtod(cursor, &end);
            if (end == cursor || errno || !isfinite(v[n]))
                break;
            n++;
            while (*end == ' ' || *end == '\t')
                end++;
            if (*end == '\n' || *end == '\r' || *end == '\0') {
                clean = true;
                break;
            }
            if (*end != ',')
                break;
            cursor = end + 1;
        }
        if (!clean || (n != 3 && n != 6) || (n == 6 && !(v[3] != 0 || v[4] != 0 || v[5] != 0))) {
            /* a header line of names (no digit in it) is allowed as the first line */
            if (line_number == 1 && !strpbrk(text, "0123456789"))
                continue;
            snprintf(error->message, sizeof(error->message),
                     "%s:%u: not x,y,z or x,y,z,nx,ny,nz (numbers; a non-zero normal)", path,
                     line_number);
            status = error->status = RAD_ERR_PARSE;
            break;
        }
        if (*count == MAX_POINTS) {
            snprintf(error->message, sizeof(error->message), "%s:%u: more than %u points", path,
                     line_number, MAX_POINTS);
            status = error->status = RAD_ERR_PARSE;
            break;
        }
        if (*count == capacity) {
            uint32_t grown = capacity ? 2 * capacity : 256;
            rad_vec3 *p = rad_resize_array(*points, grown, sizeof(**points));
            if (p)
                *points = p;
            rad_vec3 *q = p ? rad_resize_array(*normals, grown, sizeof(**normals)) : NULL;
            if (q)
                *normals = q;
            if (!p || !q) {
                snprintf(error->message, sizeof(error->message), "%s: out of memory", path);
                status = error->status = RAD_ERR_NOMEM;
                break;
            }
            capacity = grown;
        }
        (*points)[*count] = (rad_vec3){v[0], v[1], v[2]};
        (*normals)[*count] = n == 6 ? (rad_vec3){v[3], v[4], v[5]} : up;
        (*count)++;
    }
    fclose(file);
    if (status == RAD_OK && *count == 0) {
        snprintf(error->message, sizeof(error->message), "%s: no points", path);
        status = error->status = RAD_ERR_PARSE;
    }
    return status;
}

static double luminance(rad_rgb c) { return 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b; }

int command_illuminance(int argc, char **argv)
{
    cli_args args;
    cli_shared shared;
    cli_solve solve;
    const char *scene_path = NULL;
    int exit_code;
    if (!cli_begin("illuminance", usage, argc, argv, options, OPT_COUNT, &args, &shared,
                   &exit_code))
        return exit_code;
    if (!cli_scene_argument("illuminance", &args, &scene_path))
        return EXIT_USAGE;
    double height = 0, spacing = 0;
    uint32_t gather_rays = 0;
    const char *points_path = args.value[OPT_POINTS];
    if (!args.value[OPT_PLANE] == !points_path) {
        cli_error("illuminance: give one of --plane HEIGHT or --points FILE.csv");
        return EXIT_USAGE;
    }
    if ((args.value[OPT_PLANE] && !cli_parse_positive("plane", args.value[OPT_PLANE], &height)) ||
        (args.value[OPT_SPACING] &&
         !cli_parse_positive("spacing", args.value[OPT_SPACING], &spacing)) ||
        !cli_parse_count("gather-rays", args.value[OPT_GATHER_RAYS], 1, 1u << 20, &gather_rays))
        return EXIT_USAGE;
    if (!shared.output) {
        cli_error("illuminance: give -o OUT.csv");
        return EXIT_USAGE;
    }
    if (!cli_parse_solve(&args, &shared, &solve))
        return EXIT_USAGE;
    cli_parse_two_sided(&args, OPT_TWO_SIDED, &solve.two_sided);
    if (!cli_solve_outputs_writable(&shared, &solve))
        return EXIT_ERROR;

    rad_error error = {0};
    cli_solved solved;
    rad_vec3 *points = NULL, *normals = NULL;
    rad_rgb *E = NULL;
    char *table = NULL;
    uint32_t count = 0;
    double t0 = rad_clock_seconds();
    rad_status status = cli_solve_scene(scene_path, &shared, &solve, &solved, &error);
    double t_solved = rad_clock_seconds();
    if (status != RAD_OK) {
        exit_code = cli_failed(&error);
        goto done;
    }
    rad_vec3 up = solved.scene->up;
    if (points_path)
        status = read_points(points_path, up, &points, &normals, &count, &error);
    else {
        if (spacing == 0) {
            rad_vec3 lo, hi;
            rad_scene_bounds(solved.scene, &lo, &hi);
            double metres = solved.scene->unit_metres > 0 ? solved.scene->unit_metres : 1;
            double width = fmax(fmax(hi.x - lo.x, hi.y - lo.y), hi.z - lo.z);
            spacing = solved.scene->unit_metres > 0 ? 0.25 / metres : width / 40;
            (void)metres;
        }
        status = rad_work_plane(solved.scene, height, spacing, &points, &count, &error);
        if (status == RAD_OK && count == 0) {
            snprintf(error.message, sizeof(error.message),
                     "%s: no point of the work plane %g above the floor lies over a floor "
                     "(an upward-facing surface seen from above)",
                     solved.scene->source, height);
            status = error.status = RAD_ERR_INVALID;
        }
        if (status == RAD_OK) {
            normals = rad_alloc_array(1, (size_t)count * sizeof(*normals));
            if (!normals) {
                snprintf(error.message, sizeof(error.message), "out of memory");
                status = error.status = RAD_ERR_NOMEM;
            }
            for (uint32_t i = 0; normals && i < count; i++)
                normals[i] = up;
        }
    }
    if (status == RAD_OK) {
        E = rad_alloc_array(1, (size_t)(count ? count : 1) * sizeof(*E));
        rad_illuminance_options o = {.gather_rays = gather_rays, .inputs = solved.inputs,
                                     .seed = shared.seed,
                                     .threads = shared.threads};
        status = E ? rad_illuminance(solved.scene, solved.mesh, solved.B, points, normals, count,
                                     &o, E, &error)
                   : RAD_ERR_NOMEM;
    }
    /* the daylight factor is the sky's alone: with a sun, other sources or emitters the
     * illuminance is not daylight from the sky, and the column is left out */
    double sky = rad_sky_horizontal_illuminance(solved.scene);
    bool only_sky = !rad_scene_has_emitter(solved.scene);
    for (uint32_t l = 0; l < solved.scene->light_count; l++)
        only_sky &= solved.scene->lights[l].type == RAD_LIGHT_SKY;
    if (sky > 0 && !only_sky) {
        cli_warn("%s: no daylight factor: light sources or emitters besides the sky light "
                 "the scene (the factor is the sky's alone)",
                 solved.scene->source);
        sky = 0;
    }
    double e_min = INFINITY, e_max = 0, e_sum = 0;
    size_t size = 0;
    if (status == RAD_OK) {
        size_t capacity = 160 + (size_t)count * 200;
        table = rad_alloc_array(1, capacity);
        if (!table) {
            snprintf(error.message, sizeof(error.message), "out of memory");
            status = error.status = RAD_ERR_NOMEM;
        } else {
            size = (size_t)snprintf(table, capacity, "x,y,z,nx,ny,nz,E_r,E_g,E_b,E%s\n",
                                    sky > 0 ? ",daylight_factor_percent" : "");
            for (uint32_t i = 0; i < count; i++) {
                double e = luminance(E[i]);
                if (!isfinite(e)) {
                    snprintf(error.message, sizeof(error.message),
                             "illuminance at point %u is not finite (a bug: please report the "
                             "scene); nothing was written",
                             i);
                    status = error.status = RAD_ERR_INTERNAL;
                    break;
                }
                e_min = fmin(e_min, e);
                e_max = fmax(e_max, e);
                e_sum += e;
                size += (size_t)snprintf(table + size, capacity - size,
                                         "%.9g,%.9g,%.9g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g",
                                         points[i].x, points[i].y, points[i].z, normals[i].x,
                                         normals[i].y, normals[i].z, E[i].r, E[i].g, E[i].b, e);
                if (sky > 0)
                    size += (size_t)snprintf(table + size, capacity - size, ",%.6g",
                                             100 * e / sky);
                table[size++] = '\n';
            }
        }
    }
    if (status == RAD_OK)
        status = rad_write_file_atomic(shared.output, table, size, &error);
    double t_end = rad_clock_seconds();
    if (status != RAD_OK) {
        exit_code = cli_failed(&error);
        goto done;
    }
    double e_avg = e_sum / count;
    cli_stats stats;
    stats_begin(&stats);
    cli_solved_stats(&solved, &solve, &stats);
    stats_integer(&stats, "points", count);
    stats_number(&stats, "E_min", e_min);
    stats_number(&stats, "E_avg", e_avg);
    stats_number(&stats, "E_max", e_max);
    stats_number(&stats, "uniformity", e_avg > 0 ? e_min / e_avg : 0);
    if (sky > 0) {
        stats_number(&stats, "sky_horizontal_illuminance", sky);
        stats_number(&stats, "daylight_factor_avg_percent", 100 * e_avg / sky);
    }
    stats_number(&stats, "seconds_illuminance", t_end - t_solved);
    stats_number(&stats, "seconds_total", t_end - t0);
    char daylight[96] = "";
    if (sky > 0)
        snprintf(daylight, sizeof(daylight), ", daylight factor %.2f %% (min %.2f %%)",
                 100 * e_avg / sky, 100 * e_min / sky);
    exit_code = cli_finish(&stats, shared.stats_path,
                           "%u points: E_min %.4g, E_avg %.4g, E_max %.4g, uniformity %.3f%s, "
                           "%.2f s: wrote %s",
                           count, e_min, e_avg, e_max, e_avg > 0 ? e_min / e_avg : 0, daylight,
                           t_end - t0, shared.output);
done:
    cli_progress_end();
    cli_solved_free(&solved);
    free(points);
    free(normals);
    free(E);
    free(table);
    return exit_code;
}
