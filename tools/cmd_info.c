/*
 * cmd_info.c - `radiosity info [SCENE]`: what the loader read from a scene file (or the
 * built-in Cornell box): surfaces, triangles, materials, lights, emitters, bounding box,
 * camera, units and up axis, and the warnings, as text on stdout or in -o FILE.
 */
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

static const char usage[] =
    "usage: radiosity info [SCENE] [options]\n"
    "\n"
    "Tells what was read from SCENE (any file the other commands read; none = the built-in\n"
    "Cornell box): each surface (name, triangles, area, material; two-sided ones say so),\n"
    "each material (albedo, emitted radiance, specular colour), each light (type, name,\n"
    "position, direction, intensity in cd or lux, or in no known unit for Collada's and\n"
    "FBX's, a spot's cone), the emitters and their power, the bounding box, the camera the\n"
    "image commands would use, the unit and up axis when the file says, and the warnings.\n"
    "The --emit, --albedo and --two-sided options show their effect. Exit status 1 when\n"
    "the scene cannot be read.\n"
    "\n"
    CLI_TWO_SIDED_HELP
    "  -o FILE              write the report to FILE instead of stdout\n"
    "  --stats FILE.json    load time, counts (triangles to lights) and peak memory\n"
    CLI_QUIET_HELP;

enum { OPT_TWO_SIDED = OPT_OWN, OPT_COUNT };

static const cli_option options[OPT_COUNT] = {CLI_BASE_OPTIONS, CLI_SCENE_OPTIONS,
                                              [OPT_TWO_SIDED] = {"two-sided", 0, true}};

/* The report, built in memory and written at once. */
typedef struct report {
    char *text;
    size_t length, capacity;
    bool failed;
} report;

static void say(report *r, const char *format, ...) __attribute__((format(printf, 2, 3)));
static void say(report *r, const char *format, ...)
{
    va_list args;
    va_start(args, format);
    int n = vsnprintf(NULL, 0, format, args);
    va_end(args);
    if (n < 0 || r->failed)
        return;
    if (r->length + (size_t)n + 1 > r->capacity) {
        size_t capacity = (r->length + (size_t)n + 1) * 2;
        char *grown = rad_resize_array(r->text, capacity, 1);
        if (!grown) {
            r->failed = true;
            return;
        }
        r->text = grown;
        r->capacity = capacity;
    }
    va_start(args, format);
    vsnprintf(r->text + r->length, r->capacity - r->length, format, args);
    va_end(args);
    r->length += (size_t)n;
}

/* Warnings the loader sent, kept for the report. */
typedef struct warnings {
    report lines;
    unsigned count;
} warnings;

static void keep_warning(void *user, const char *message)
{
    warnings *w = user;
    say(&w->lines, "  %s\n", message);
    w->count++;
}

static double triangle_area(const rad_scene *scene, uint32_t t)
{
    const uint32_t *v = scene->triangles[t].vertex;
    const rad_vec3 *p = scene->positions;
    double a[3] = {p[v[1]].x - p[v[0]].x, p[v[1]].y - p[v[0]].y, p[v[1]].z - p[v[0]].z};
    double b[3] = {p[v[2]].x - p[v[0]].x, p[v[2]].y - p[v[0]].y, p[v[2]].z - p[v[0]].z};
    double c[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
    return 0.5 * sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
}

static bool emits(const rad_material *m)
{
    return m->emission.r > 0 || m->emission.g > 0 || m->emission.b > 0;
}

static const char *axis_name(rad_vec3 up)
{
    static const char *names[] = {"+x", "+y", "+z", "-x", "-y", "-z"};
    const double *u = &up.x;
    for (int a = 0; a < 3; a++)
        if (fabs(u[a]) == 1)
            return names[a + (u[a] < 0 ? 3 : 0)];
    return "oblique";
}

/* A component of a unit vector as shown with 6 digits: float noise below that (a
 * rotation by 90 degrees in single precision leaves 4e-8) and -0 shown as 0. */
static double shown(double v)
{
    return fabs(v) < 5e-7 ? 0 : v;
}

/* One line per light: type, name, where it is and where it points (as the type has
 * them), its intensity in its unit (or in none, for Collada's and FBX's), a spot's cone
 * half-angles. */
static void describe_lights(report *r, const rad_scene *scene)
{
    say(r, "lights: %u\n", scene->light_count);
    for (uint32_t l = 0; l < scene->light_count; l++) {
        const rad_light *light = &scene->lights[l];
        rad_light_type type = light->type;
        bool placed = type == RAD_LIGHT_POINT || type == RAD_LIGHT_SPOT ||
                      type == RAD_LIGHT_LUMINAIRE;
        bool directed = type == RAD_LIGHT_SPOT || type == RAD_LIGHT_DIRECTIONAL ||
                        type == RAD_LIGHT_LUMINAIRE;
        const char *unit = type == RAD_LIGHT_POINT || type == RAD_LIGHT_SPOT ? " cd"
                           : type == RAD_LIGHT_DIRECTIONAL                   ? " lux"
                           : type == RAD_LIGHT_SKY                           ? " cd/m^2 (zenith)"
                                                                             : " (factor)";
        say(r, "  %-11s %-24s", rad_light_type_name(type), light->name);
        if (placed)
            say(r, "  position (%.6g, %.6g, %.6g)", light->position.x + 0.0,
                light->position.y + 0.0, light->position.z + 0.0); /* + 0.0: no -0 */
        if (directed)
            say(r, "  direction (%.6g, %.6g, %.6g)", shown(light->direction.x),
                shown(light->direction.y), shown(light->direction.z));
        say(r, "  intensity (%.6g, %.6g, %.6g)%s%s%s", light->intensity.r, light->intensity.g,
            light->intensity.b, light->unit_unknown ? " in no known unit (taken as" : "", unit,
            light->unit_unknown ? ")" : "");
        if (type == RAD_LIGHT_SPOT)
            say(r, "  cone %.5g to %.5g degrees from the axis", light->inner_degrees,
                light->outer_degrees);
        say(r, "\n");
    }
}

static void describe(report *r, const rad_scene *scene)
{
    rad_vec3 lo, hi;
    rad_scene_bounds(scene, &lo, &hi);
    say(r, "scene: %s\n", scene->source);
    say(r, "triangles: %u\nvertices: %u (shared positions after welding)\n",
        scene->triangle_count, scene->position_count);
    say(r, "area: %.6g\n", rad_scene_area(scene));
    say(r, "bounding box: (%.6g, %.6g, %.6g) to (%.6g, %.6g, %.6g), size %.6g x %.6g x %.6g\n",
        lo.x, lo.y, lo.z, hi.x, hi.y, hi.z, hi.x - lo.x, hi.y - lo.y, hi.z - lo.z);
    if (scene->unit_metres > 0)
        say(r, "unit: %.6g m\n", scene->unit_metres);
    else
        say(r, "unit: not given by the file\n");
    say(r, "up axis: %s\n", axis_name(scene->up));
    rad_camera c = scene->has_camera ? scene->camera : rad_scene_default_camera(scene);
    say(r, "camera: %s: eye (%.6g, %.6g, %.6g), target (%.6g, %.6g, %.6g), up (%.6g, %.6g, "
           "%.6g), vertical fov %.6g degrees\n",
        scene->has_camera ? "from the scene" : "none in the file; the default view", c.eye.x,
        c.eye.y, c.eye.z, c.target.x, c.target.y, c.target.z, c.up.x, c.up.y, c.up.z,
        c.fov_degrees);

    /* per material: triangles and area using it */
    uint32_t nm = scene->material_count;
    double *material_area = rad_alloc_array(nm ? nm : 1, sizeof(double));
    double *radiating_area = rad_alloc_array(nm ? nm : 1, sizeof(double)); /* two-sided: twice */
    uint32_t *material_triangles = rad_alloc_array(nm ? nm : 1, sizeof(uint32_t));
    uint32_t *listed_for = rad_alloc_array(nm ? nm : 1, sizeof(uint32_t)); /* surface + 1 */
    if (!material_area || !radiating_area || !material_triangles || !listed_for) {
        r->failed = true;
        free(material_area);
        free(radiating_area);
        free(material_triangles);
        free(listed_for);
        return;
    }
    say(r, "surfaces: %u\n", scene->surface_count);
    for (uint32_t s = 0; s < scene->surface_count; s++) {
        const rad_surface *surface = &scene->surfaces[s];
        double area = 0;
        uint32_t end = surface->first_triangle + surface->triangle_count;
        for (uint32_t t = surface->first_triangle; t < end; t++) {
            double a = triangle_area(scene, t);
            uint32_t m = scene->triangles[t].material;
            area += a;
            material_area[m] += a;
            radiating_area[m] += surface->flags & RAD_SURFACE_TWO_SIDED ? 2 * a : a;
            material_triangles[m]++;
        }
        /* the materials of this surface, in order of first use */
        say(r, "  %-24s %8u triangles  area %-12.6g material", surface->name,
            surface->triangle_count, area);
        unsigned listed = 0;
        for (uint32_t t = surface->first_triangle; t < end && listed <= 3; t++) {
            uint32_t m = scene->triangles[t].material;
            if (listed_for[m] == s + 1)
                continue;
            listed_for[m] = s + 1;
            say(r, listed == 3 ? ", ..." : "%s %s", listed ? "," : "", scene->materials[m].name);
            listed++;
        }
        say(r, "%s\n", surface->flags & RAD_SURFACE_TWO_SIDED ? "  (two-sided)" : "");
    }
    say(r, "materials: %u\n", nm);
    for (uint32_t m = 0; m < nm; m++) {
        const rad_material *material = &scene->materials[m];
        say(r, "  %-24s albedo (%.4g, %.4g, %.4g)%s  emission (%.4g, %.4g, %.4g)%s",
            material->name, material->albedo.r, material->albedo.g, material->albedo.b,
            material->albedo_texture ? " x texture" : "", material->emission.r,
            material->emission.g, material->emission.b,
            material->emission_texture ? " x texture" : "");
        const rad_rgb *ks = &material->specular;
        if (ks->r > 0 || ks->g > 0 || ks->b > 0)
            say(r, "  specular (%.4g, %.4g, %.4g)", ks->r, ks->g, ks->b);
        say(r, "  %u triangles%s\n", material_triangles[m],
            material_triangles[m] ? "" : " (unused)");
    }
    describe_lights(r, scene);
    unsigned emitters = 0;
    for (uint32_t m = 0; m < nm; m++)
        emitters += emits(&scene->materials[m]) && material_triangles[m];
    say(r, "emitters: %u\n", emitters);
    for (uint32_t m = 0; m < nm; m++) {
        const rad_material *material = &scene->materials[m];
        if (!emits(material) || !material_triangles[m])
            continue;
        /* power of a Lambertian emitter: pi L_e A (per unit of the scene's length squared),
         * A counting both sides of two-sided surfaces; with an emission texture, times the
         * texture's mean over the surface (not shown) */
        double k = 3.14159265358979323846 * radiating_area[m];
        say(r, "  %-24s radiance (%.4g, %.4g, %.4g)%s  area %.6g  power (%.6g, %.6g, %.6g)%s\n",
            material->name, material->emission.r, material->emission.g, material->emission.b,
            material->emission_texture ? " x texture" : "", material_area[m],
            k * material->emission.r, k * material->emission.g, k * material->emission.b,
            material->emission_texture ? " x the texture's mean" : "");
    }
    say(r, "textures: %u\n", scene->texture_count);
    for (uint32_t t = 0; t < scene->texture_count; t++) {
        const rad_texture *texture = &scene->textures[t];
        say(r, "  %s  %u x %u  used by", texture->source, texture->width, texture->height);
        for (uint32_t m = 0; m < nm; m++)
        {
            if (scene->materials[m].albedo_texture == t + 1)
                say(r, " %s (albedo)", scene->materials[m].name);
            if (scene->materials[m].emission_texture == t + 1)
                say(r, " %s (emission)", scene->materials[m].name);
        }
        say(r, "\n");
    }
    free(listed_for);
    free(material_area);
    free(radiating_area);
    free(material_triangles);
}

int command_info(int argc, char **argv)
{
    cli_args args;
    cli_shared shared;
    const char *path;
    int exit_code;
    if (!cli_begin("info", usage, argc, argv, options, OPT_COUNT, &args, &shared, &exit_code))
        return exit_code;
    if (!cli_scene_argument("info", &args, &path))
        return EXIT_USAGE;
    if (!cli_outputs_writable((const char *[]){shared.output, shared.stats_path}, 2))
        return EXIT_ERROR;

    warnings w = {{0}, 0};
    rad_scene *scene = NULL;
    rad_error error = {0};
    double t0 = rad_clock_seconds();
    rad_status status = cli_load_scene_logged(path, keep_warning, &w, &scene, &error);
    cli_two_sided two_sided;
    cli_parse_two_sided(&args, OPT_TWO_SIDED, &two_sided);
    if (status == RAD_OK)
        status = cli_apply_two_sided(&two_sided, scene, &error);
    double t_load = rad_clock_seconds() - t0;
    report r = {0};
    if (status != RAD_OK) {
        /* the warnings that led up to the error still help */
        if (w.lines.text)
            fputs(w.lines.text, stderr);
        exit_code = cli_failed(&error);
        goto done;
    }
    describe(&r, scene);
    say(&r, "warnings: %u\n%s", w.count, w.lines.text ? w.lines.text : "");
    if (r.failed || w.lines.failed) {
        cli_error("out of memory");
        exit_code = EXIT_ERROR;
        goto done;
    }
    if (shared.output) {
        if (rad_write_file_atomic(shared.output, r.text, r.length, &error) != RAD_OK) {
            exit_code = cli_failed(&error);
            goto done;
        }
    } else {
        fwrite(r.text, 1, r.length, stdout);
    }
    cli_stats stats;
    stats_begin(&stats);
    stats_string(&stats, "scene", scene->source);
    stats_integer(&stats, "triangles", scene->triangle_count);
    stats_integer(&stats, "vertices", scene->position_count);
    stats_integer(&stats, "surfaces", scene->surface_count);
    stats_integer(&stats, "materials", scene->material_count);
    stats_integer(&stats, "lights", scene->light_count);
    stats_integer(&stats, "warnings", w.count);
    stats_number(&stats, "seconds_load", t_load);
    exit_code = cli_finish(&stats, shared.stats_path,
                           "%u triangles, %u surfaces, %u materials, %u lights, %u warnings, "
                           "%.2f s: wrote %s",
                           scene->triangle_count, scene->surface_count, scene->material_count,
                           scene->light_count, w.count, t_load,
                           shared.output ? shared.output : "standard output");
done:
    free(r.text);
    free(w.lines.text);
    rad_scene_destroy(scene);
    return exit_code;
}
