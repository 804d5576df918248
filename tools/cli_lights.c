/*
 * cli_lights.c - the light-source options every command that loads a scene takes
 * (--point, --spot, --sun with --time, --sky, --luminaire, --environment, --unit,
 * --north): parsed with the other shared options, then added to the scene after it is
 * loaded (cli_load_scene).
 */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

#define MAX_FIELDS 8
#define PI 3.14159265358979323846
#define DEFAULT_SUN_LUX 100000.0      /* direct normal illuminance of a clear day's sun */
#define DEFAULT_SUN_DIAMETER 0.53     /* degrees */
#define DEFAULT_SKY_LUX 10000.0       /* an open horizontal plane under the default sky */

typedef struct light_spec {
    int option;        /* OPT_POINT, ... */
    const char *text;  /* as given */
} light_spec;

static light_spec specs[CLI_MAX_GIVEN];
static int spec_count;
static const char *unit_text, *north_text, *time_text, *rotate_text;

/* Fills `error` (when not NULL) and returns `status`. */
static rad_status fail(rad_error *error, rad_status status, const char *format, ...)
    __attribute__((format(printf, 3, 4)));
static rad_status fail(rad_error *error, rad_status status, const char *format, ...)
{
    if (error) {
        va_list args;
        va_start(args, format);
        vsnprintf(error->message, sizeof(error->message), format, args);
        va_end(args);
        error->status = status;
    }
    return status;
}

/* Splits a copy of `text` at ':' into at most MAX_FIELDS fields. */
static int split_fields(const char *text, char *copy, size_t size, char **fields)
{
    snprintf(copy, size, "%s", text);
    int count = 0;
    char *cursor = copy;
    while (count < MAX_FIELDS) {
        fields[count++] = cursor;
        char *colon = strchr(cursor, ':');
        if (!colon)
            break;
        *colon = '\0';
        cursor = colon + 1;
    }
    return strchr(cursor, ':') ? -1 : count;
}

/* "a,b,c" into up to `max` finite numbers; the count, or -1. */
static int parse_numbers(const char *text, double *out, int max)
{
    int count = 0;
    const char *cursor = text;
    for (;;) {
        char *end;
        errno = 0;
        double v = strtod(cursor, &end);
        if (end == cursor || errno != 0 || !isfinite(v) || count == max)
            return -1;
        out[count++] = v;
        if (*end == '\0')
            return count;
        if (*end != ',')
            return -1;
        cursor = end + 1;
    }
}

static bool parse_vector(const char *option, const char *text, const char *what, rad_vec3 *v)
{
    double n[3];
    if (parse_numbers(text, n, 3) != 3) {
        cli_error("--%s: '%s' is not %s X,Y,Z", option, text, what);
        return false;
    }
    *v = (rad_vec3){n[0], n[1], n[2]};
    return true;
}

static bool parse_number(const char *option, const char *text, const char *what, double *v)
{
    if (parse_numbers(text, v, 1) != 1) {
        cli_error("--%s: '%s' is not a number (%s)", option, text, what);
        return false;
    }
    return true;
}

/* R,G,B (a colour factor), default 1,1,1. */
static bool parse_colour(const char *option, const char *text, rad_rgb *colour)
{
    rad_vec3 v = {1, 1, 1};
    if (text && !parse_vector(option, text, "a colour", &v))
        return false;
    *colour = (rad_rgb){v.x, v.y, v.z};
    return true;
}

static const char *option_name(int option)
{
    switch (option) {
    case OPT_POINT:
        return "point";
    case OPT_SPOT:
        return "spot";
    case OPT_SUN:
        return "sun";
    case OPT_SKY:
        return "sky";
    case OPT_LUMINAIRE:
        return "luminaire";
    default:
        return "environment";
    }
}

/* The light of one option, without what needs the scene (the sun's place, files). *place
 * is set for a sun given by latitude and longitude. */
static bool build_light(const light_spec *spec, rad_light *light, bool *place, double *lat_lon)
{
    const char *option = option_name(spec->option);
    char copy[1024], *f[MAX_FIELDS];
    int n = split_fields(spec->text, copy, sizeof(copy), f);
    memset(light, 0, sizeof(*light));
    *place = false;
    snprintf(light->name, sizeof(light->name), "--%s %s", option, spec->text);
    rad_rgb colour = {1, 1, 1};
    double intensity = 0;
    switch (spec->option) {
    case OPT_POINT:
        light->type = RAD_LIGHT_POINT;
        if (n < 2 || n > 3) {
            cli_error("--point: '%s' is not X,Y,Z:CANDELA[:R,G,B]", spec->text);
            return false;
        }
        if (!parse_vector(option, f[0], "a position", &light->position) ||
            !parse_number(option, f[1], "candela", &intensity) ||
            !parse_colour(option, n > 2 ? f[2] : NULL, &colour))
            return false;
        break;
    case OPT_SPOT:
        light->type = RAD_LIGHT_SPOT;
        if (n < 5 || n > 6) {
            cli_error("--spot: '%s' is not X,Y,Z:DX,DY,DZ:CANDELA:INNER:OUTER[:R,G,B]",
                      spec->text);
            return false;
        }
        if (!parse_vector(option, f[0], "a position", &light->position) ||
            !parse_vector(option, f[1], "a direction", &light->direction) ||
            !parse_number(option, f[2], "candela", &intensity) ||
            !parse_number(option, f[3], "inner half-angle, degrees", &light->inner_degrees) ||
            !parse_number(option, f[4], "outer half-angle, degrees", &light->outer_degrees) ||
            !parse_colour(option, n > 5 ? f[5] : NULL, &colour))
            return false;
        break;
    case OPT_SUN: {
        light->type = RAD_LIGHT_DIRECTIONAL;
        intensity = DEFAULT_SUN_LUX;
        light->angular_diameter_degrees = DEFAULT_SUN_DIAMETER;
        double where[3];
        int k = n >= 1 && n <= 3 ? parse_numbers(f[0], where, 3) : -1;
        if (k != 2 && k != 3) {
            cli_error("--sun: '%s' is not X,Y,Z[:LUX[:DIAMETER]] (toward the sun) or "
                      "LATITUDE,LONGITUDE[:LUX[:DIAMETER]] (with --time)",
                      spec->text);
            return false;
        }
        if ((n > 1 && !parse_number(option, f[1], "lux", &intensity)) ||
            (n > 2 && !parse_number(option, f[2], "angular diameter, degrees",
                                    &light->angular_diameter_degrees)))
            return false;
        if (k == 3 && where[0] == 0 && where[1] == 0 && where[2] == 0) {
            cli_error("--sun: '%s': the direction toward the sun is zero", spec->text);
            return false;
        }
        if (k == 3)
            light->direction = (rad_vec3){-where[0], -where[1], -where[2]};
        else {
            *place = true;
            lat_lon[0] = where[0];
            lat_lon[1] = where[1];
        }
        break;
    }
    case OPT_SKY: {
        light->type = RAD_LIGHT_SKY;
        if (n < 1 || n > 2) {
            cli_error("--sky: '%s' is not uniform|cie-overcast|cie-clear[:ZENITH_LUMINANCE]",
                      spec->text);
            return false;
        }
        if (strcmp(f[0], "uniform") == 0)
            light->sky = RAD_SKY_UNIFORM;
        else if (strcmp(f[0], "cie-overcast") == 0 || strcmp(f[0], "overcast") == 0)
            light->sky = RAD_SKY_CIE_OVERCAST;
        else if (strcmp(f[0], "cie-clear") == 0 || strcmp(f[0], "clear") == 0)
            light->sky = RAD_SKY_CIE_CLEAR;
        else {
            cli_error("--sky: unknown sky '%s' (uniform, cie-overcast or cie-clear)", f[0]);
            return false;
        }
        intensity = -1; /* the default: set once the sun is known */
        if (n > 1) {
            if (!parse_number(option, f[1], "zenith luminance, cd/m^2", &intensity))
                return false;
            if (!(intensity >= 0)) {
                cli_error("--sky: '%s': the zenith luminance must not be negative", spec->text);
                return false;
            }
        }
        break;
    }
    case OPT_LUMINAIRE:
        light->type = RAD_LIGHT_LUMINAIRE;
        intensity = 1;
        if (n < 2 || n > 4 || f[0][0] == '\0') {
            cli_error("--luminaire: '%s' is not FILE.ies:X,Y,Z[:AIMX,AIMY,AIMZ[:FACTOR]]",
                      spec->text);
            return false;
        }
        if (!parse_vector(option, f[1], "a position", &light->position) ||
            (n > 2 && f[2][0] && !parse_vector(option, f[2], "an aim (the nadir)", &light->direction)) ||
            (n > 3 && !parse_number(option, f[3], "factor", &intensity)))
            return false;
        break;
    case OPT_ENVIRONMENT:
        light->type = RAD_LIGHT_ENVIRONMENT;
        intensity = 1;
        if (n < 1 || n > 2 || f[0][0] == '\0') {
            cli_error("--environment: '%s' is not FILE.hdr|.exr|.pfm[:SCALE]", spec->text);
            return false;
        }
        if (n > 1 && !parse_number(option, f[1], "scale", &intensity))
            return false;
        if (rotate_text && !parse_number("environment-rotate", rotate_text, "degrees",
                                         &light->rotate_degrees))
            return false;
        break;
    default:
        cli_error("--%s: not available yet", option);
        return false;
    }
    if (spec->option != OPT_SKY && !(intensity >= 0)) {
        cli_error("--%s: '%s': the intensity must not be negative", option, spec->text);
        return false;
    }
    light->intensity = (rad_rgb){intensity * colour.r, intensity * colour.g, intensity * colour.b};
    return true;
}

bool cli_parse_lights(const cli_args *args)
{
    spec_count = 0;
    unit_text = args->value[OPT_UNIT];
    north_text = args->value[OPT_NORTH];
    time_text = args->value[OPT_TIME];
    rotate_text = args->value[OPT_ENVIRONMENT_ROTATE];
    for (int k = 0; k < args->given_count; k++) {
        int option = args->given_option[k];
        if (option != OPT_POINT && option != OPT_SPOT && option != OPT_SUN &&
            option != OPT_SKY && option != OPT_LUMINAIRE && option != OPT_ENVIRONMENT)
            continue;
        specs[spec_count++] = (light_spec){option, args->given_value[k]};
    }
    /* everything that can be checked without the scene is checked now, before any work */
    bool sun_by_place = false;
    for (int k = 0; k < spec_count; k++) {
        rad_light light;
        bool place;
        double lat_lon[2];
        if (!build_light(&specs[k], &light, &place, lat_lon))
            return false;
        sun_by_place |= place;
    }
    if (sun_by_place && !time_text) {
        cli_error("--sun LATITUDE,LONGITUDE needs --time YYYY-MM-DDTHH:MM[+HH:MM]");
        return false;
    }
    if (time_text && !sun_by_place) {
        cli_error("--time places the sun: it goes with --sun LATITUDE,LONGITUDE");
        return false;
    }
    if (unit_text && strcmp(unit_text, "m") != 0 && strcmp(unit_text, "cm") != 0 &&
        strcmp(unit_text, "mm") != 0 && strcmp(unit_text, "in") != 0 &&
        strcmp(unit_text, "ft") != 0) {
        cli_error("--unit: '%s' is not m, cm, mm, in or ft", unit_text);
        return false;
    }
    rad_vec3 north;
    if (north_text && !parse_vector("north", north_text, "a direction", &north))
        return false;
    return true;
}

/* --time YYYY-MM-DDTHH:MM[:SS][+HH[:MM]|-HH[:MM]|Z]: local time and its UTC offset. */
static bool parse_time(const char *text, rad_place_time *when, rad_error *error)
{
    int year, month, day, hour, minute, consumed = 0;
    double second = 0;
    if (sscanf(text, "%4d-%2d-%2dT%2d:%2d%n", &year, &month, &day, &hour, &minute,
               &consumed) != 5 ||
        minute < 0 || minute > 59 || hour < 0)
        goto bad;
    const char *rest = text + consumed;
    if (*rest == ':') {
        char *end;
        second = strtod(rest + 1, &end);
        if (end == rest + 1 || !(second >= 0 && second < 61))
            goto bad;
        rest = end;
    }
    double offset = 0;
    if (*rest == '+' || *rest == '-') {
        int oh = 0, om = 0, used = 0;
        if (sscanf(rest + 1, "%2d%n", &oh, &used) != 1)
            goto bad;
        const char *tail = rest + 1 + used;
        if (*tail == ':' && sscanf(tail + 1, "%2d%n", &om, &used) == 1)
            tail += 1 + used;
        if (*tail != '\0')
            goto bad;
        offset = (*rest == '-' ? -1 : 1) * (oh + om / 60.0);
    } else if (!(*rest == '\0' || (rest[0] == 'Z' && rest[1] == '\0')))
        goto bad;
    when->year = year;
    when->month = month;
    when->day = day;
    when->hour = hour + minute / 60.0 + second / 3600.0;
    when->utc_offset_hours = offset;
    return true;
bad:
    fail(error, RAD_ERR_INVALID,
             "--time: '%s' is not YYYY-MM-DDTHH:MM[+HH:MM] (local time, its offset from UTC)",
             text);
    return false;
}

static double unit_metres(const char *unit)
{
    return strcmp(unit, "m") == 0    ? 1
           : strcmp(unit, "cm") == 0 ? 0.01
           : strcmp(unit, "mm") == 0 ? 0.001
           : strcmp(unit, "in") == 0 ? 0.0254
                                     : 0.3048;
}

/* Prefixes error's message with the option that caused it. */
static rad_status blame(rad_status status, const char *option, rad_error *error)
{
    if (status != RAD_OK && error) {
        char message[RAD_ERROR_MESSAGE_MAX];
        snprintf(message, sizeof(message), "%s", error->message);
        snprintf(error->message, sizeof(error->message), "--%s: %.900s", option, message);
    }
    return status;
}

rad_status cli_apply_lights(rad_scene *scene, rad_log_fn log, void *log_user,
                            rad_error *error)
{
    if (unit_text)
        scene->unit_metres = unit_metres(unit_text);
    if (north_text) {
        rad_vec3 north;
        parse_numbers(north_text, &north.x, 3);
        rad_vec3 up = scene->up;
        double along = north.x * up.x + north.y * up.y + north.z * up.z;
        rad_vec3 flat = {north.x - along * up.x, north.y - along * up.y, north.z - along * up.z};
        if (!(sqrt(flat.x * flat.x + flat.y * flat.y + flat.z * flat.z) > 1e-9))
            return fail(error, RAD_ERR_INVALID,
                            "--north: %s is along the scene's up axis, not a horizontal direction",
                            north_text);
        scene->north = flat;
    }
    rad_vec3 up = scene->up, north = rad_scene_north(scene);
    rad_vec3 east = {north.y * up.z - north.z * up.y, north.z * up.x - north.x * up.z,
                     north.x * up.y - north.y * up.x};
    /* suns first: a clear sky takes the last sun's direction */
    bool have_sun = false;
    rad_vec3 sun_travel = {0, 0, 0};
    for (int pass = 0; pass < 2; pass++)
        for (int k = 0; k < spec_count; k++) {
            bool is_sun = specs[k].option == OPT_SUN;
            if ((pass == 0) != is_sun)
                continue;
            rad_light light;
            bool place;
            double lat_lon[2];
            build_light(&specs[k], &light, &place, lat_lon);
            if (place) {
                rad_place_time when = {.latitude = lat_lon[0], .longitude = lat_lon[1]};
                double azimuth, elevation;
                if (!parse_time(time_text, &when, error))
                    return RAD_ERR_INVALID;
                rad_status status = rad_sun_position(&when, &azimuth, &elevation, error);
                if (status != RAD_OK)
                    return blame(status, "sun", error);
                double a = azimuth * (PI / 180), h = elevation * (PI / 180);
                rad_vec3 toward = {cos(h) * (cos(a) * north.x + sin(a) * east.x) + sin(h) * up.x,
                                   cos(h) * (cos(a) * north.y + sin(a) * east.y) + sin(h) * up.y,
                                   cos(h) * (cos(a) * north.z + sin(a) * east.z) + sin(h) * up.z};
                light.direction = (rad_vec3){-toward.x, -toward.y, -toward.z};
                snprintf(light.name, sizeof(light.name),
                         "sun at %.4g,%.4g %s: azimuth %.2f, elevation %.2f degrees",
                         lat_lon[0], lat_lon[1], time_text, azimuth, elevation);
            }
            if (is_sun) {
                double d = light.direction.x * up.x + light.direction.y * up.y +
                           light.direction.z * up.z;
                have_sun = true;
                sun_travel = light.direction;
                if (!(d < 0)) {
                    if (log) {
                        char message[1200];
                        snprintf(message, sizeof(message),
                                 "--sun %s: the sun is below the horizon: no sunlight",
                                 specs[k].text);
                        log(log_user, message);
                    }
                    continue;
                }
            }
            if (light.type == RAD_LIGHT_SKY) {
                if (light.sky == RAD_SKY_CIE_CLEAR) {
                    if (!have_sun)
                        return fail(error, RAD_ERR_INVALID,
                                        "--sky %s: a clear sky needs the sun: give --sun too",
                                        specs[k].text);
                    light.direction = sun_travel;
                }
                if (light.intensity.r < 0) {
                    /* the zenith luminance that gives DEFAULT_SKY_LUX on open ground */
                    double sun_elevation = 0;
                    if (light.sky == RAD_SKY_CIE_CLEAR) {
                        double d = -(sun_travel.x * up.x + sun_travel.y * up.y + sun_travel.z * up.z) /
                                   sqrt(sun_travel.x * sun_travel.x + sun_travel.y * sun_travel.y +
                                        sun_travel.z * sun_travel.z);
                        sun_elevation = asin(fmin(fmax(d, -1), 1));
                    }
                    double lz = DEFAULT_SKY_LUX / rad_sky_horizontal_factor(light.sky, sun_elevation);
                    light.intensity = (rad_rgb){lz, lz, lz};
                }
            }
            if (light.type == RAD_LIGHT_LUMINAIRE) {
                char copy[1024], *f[MAX_FIELDS];
                split_fields(specs[k].text, copy, sizeof(copy), f);
                if (light.direction.x == 0 && light.direction.y == 0 && light.direction.z == 0)
                    light.direction = (rad_vec3){-up.x, -up.y, -up.z}; /* aimed straight down */
                rad_photometry *web = NULL;
                rad_status status = rad_photometry_read(f[0], log, log_user, &web, error);
                if (status != RAD_OK)
                    return blame(status, "luminaire", error);
                light.photometry = web;
                status = rad_scene_add_light(scene, &light, error);
                if (status != RAD_OK) {
                    rad_photometry_destroy(web);
                    return blame(status, "luminaire", error);
                }
                continue;
            }
            if (light.type == RAD_LIGHT_ENVIRONMENT) {
                char copy[1024], *f[MAX_FIELDS];
                split_fields(specs[k].text, copy, sizeof(copy), f);
                rad_image *map = NULL;
                rad_status status = rad_image_read(f[0], &map, error);
                if (status != RAD_OK)
                    return blame(status, "environment", error);
                if (map->width != 2 * map->height) {
                    fail(error, RAD_ERR_INVALID,
                         "--environment: %s is %ux%u: an equirectangular map is twice as wide "
                         "as high",
                         f[0], map->width, map->height);
                    rad_image_destroy(map);
                    return RAD_ERR_INVALID;
                }
                light.environment = map;
                status = rad_scene_add_light(scene, &light, error);
                if (status != RAD_OK) {
                    rad_image_destroy(map);
                    return blame(status, "environment", error);
                }
                continue;
            }
            rad_status status = rad_scene_add_light(scene, &light, error);
            if (status != RAD_OK)
                return blame(status, option_name(specs[k].option), error);
        }
    return RAD_OK;
}
