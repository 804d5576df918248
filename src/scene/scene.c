/*
 * scene.c - queries on a loaded rad_scene: area, bounds, emitters, a framing camera;
 * and changing a surface's or material's values or flags after loading (command-line
 * overrides), with the one rule for finding what a NAME the user typed means.
 *
 * A NAME means, in this order: the surface of exactly that name; else every material of
 * exactly that name (exporters repeat names: "Material" in each object); else the same
 * two steps ignoring case, when that leaves one name. Several names ignoring case, or none
 * at all, is an error that lists them, or says the closest name by edit distance.
 */
#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/error.h"
#include "core/vec3.h"
#include "radiosity.h"
#include "lights/scene_lights.h"
#include "scene/material_at.h"

void rad_scene_destroy(rad_scene *scene)
{
    if (!scene)
        return;
    free(scene->positions);
    free(scene->triangles);
    free(scene->materials);
    free(scene->surfaces);
    for (uint32_t t = 0; t < scene->texture_count; t++)
        free(scene->textures[t].rgb);
    free(scene->textures);
    free(scene->uv);
    scene_lights_free(scene);
    free(scene);
}

double rad_scene_area(const rad_scene *scene)
{
    double area = 0;
    for (uint32_t t = 0; t < scene->triangle_count; t++) {
        const uint32_t *v = scene->triangles[t].vertex;
        rad_vec3 e0 = v3_sub(scene->positions[v[1]], scene->positions[v[0]]);
        rad_vec3 e1 = v3_sub(scene->positions[v[2]], scene->positions[v[0]]);
        area += 0.5 * v3_length(v3_cross(e0, e1));
    }
    return area;
}

void rad_scene_bounds(const rad_scene *scene, rad_vec3 *lo, rad_vec3 *hi)
{
    v3_bounds(scene->positions, scene->position_count, lo, hi);
}

bool rad_scene_has_emitter(const rad_scene *scene)
{
    /* each emitting material once (an emission texture is scanned whole), then its use */
    for (uint32_t m = 0; m < scene->material_count; m++) {
        if (!material_emits(scene, m))
            continue;
        for (uint32_t t = 0; t < scene->triangle_count; t++)
            if (scene->triangles[t].material == m)
                return true;
    }
    return false;
}

/* The scene's up axis, snapped to the nearest coordinate axis with its sign; y when unset. */
static int up_axis(const rad_scene *scene, double *sign)
{
    const double *u = &scene->up.x;
    int axis = 1;
    for (int a = 0; a < 3; a++)
        if (fabs(u[a]) > fabs(u[axis]))
            axis = a;
    *sign = u[axis] < 0 ? -1 : 1;
    return axis;
}

rad_camera rad_scene_default_camera(const rad_scene *scene)
{
    rad_vec3 lo, hi;
    rad_scene_bounds(scene, &lo, &hi);
    rad_vec3 center = v3_scale(v3_add(lo, hi), 0.5);
    const rad_vec3 half = v3_scale(v3_sub(hi, lo), 0.5);
    const double *h = &half.x;
    /* y up: look along +z; z up: along +y (the front view of z-up modellers); x up: +z */
    double sign;
    int up = up_axis(scene, &sign);
    int depth = up == 2 ? 1 : 2;
    int side = 3 - up - depth;
    rad_camera camera;
    camera.fov_degrees = 40.0;
    double tan_half = tan(camera.fov_degrees * RAD_PI / 360.0);
    /* back off until the front face's larger half extent fits the narrower (vertical) fov */
    double extent = fmax(h[side], h[up]);
    double distance = extent / tan_half + h[depth];
    if (!(distance > 0))
        distance = 1;
    camera.eye = center;
    (&camera.eye.x)[depth] -= distance * 1.05;
    camera.target = center;
    camera.up = v3(0, 0, 0);
    (&camera.up.x)[up] = sign;
    return camera;
}

/* Albedo in [0,1] and emission >= 0, finite. */
static bool rgb_in(const rad_rgb *c, double hi)
{
    const double *v = &c->r;
    for (int k = 0; k < 3; k++)
        if (!(v[k] >= 0 && v[k] <= hi))
            return false;
    return true;
}

/* Appends a copy of material m; UINT32_MAX when out of memory. */
static uint32_t copy_material(rad_scene *scene, uint32_t m)
{
    if (scene->material_count >= UINT32_MAX - 1)
        return UINT32_MAX;
    rad_material *grown = rad_resize_array(scene->materials, scene->material_count + 1,
                                           sizeof(*scene->materials));
    if (!grown)
        return UINT32_MAX;
    scene->materials = grown;
    grown[scene->material_count] = grown[m];
    return scene->material_count++;
}

static void apply(rad_material *m, const rad_rgb *albedo, const rad_rgb *emission)
{
    if (albedo)
        m->albedo = *albedo;
    if (emission)
        m->emission = *emission;
}

/* What a NAME resolved to: one surface, or the name every chosen material has. */
typedef struct name_match {
    uint32_t surface;       /* the surface, or UINT32_MAX */
    const char *material;   /* the materials' name (a scene material's own), or NULL */
} name_match;

static bool same_name(const char *a, const char *b, bool ignore_case)
{
    if (!ignore_case)
        return strcmp(a, b) == 0;
    for (; *a && *b; a++, b++)
        if (tolower((unsigned char)*a) != tolower((unsigned char)*b))
            return false;
    return *a == *b;
}

static size_t length_at_most(const char *text, size_t most)
{
    size_t n = 0;
    while (n < most && text[n])
        n++;
    return n;
}

/* Levenshtein distance, case ignored, of two names (at most 127 characters each: the
 * longer ones are cut there). */
static unsigned edit_distance(const char *a, const char *b)
{
    enum { MAX = 128 };
    unsigned row[MAX + 1];
    size_t n = length_at_most(b, MAX), m = length_at_most(a, MAX);
    for (size_t j = 0; j <= n; j++)
        row[j] = (unsigned)j;
    for (size_t i = 1; i <= m; i++) {
        unsigned diagonal = row[0];
        row[0] = (unsigned)i;
        for (size_t j = 1; j <= n; j++) {
            unsigned above = row[j];
            unsigned change = diagonal + (tolower((unsigned char)a[i - 1]) !=
                                          tolower((unsigned char)b[j - 1]));
            unsigned best = above + 1 < row[j - 1] + 1 ? above + 1 : row[j - 1] + 1;
            row[j] = change < best ? change : best;
            diagonal = above;
        }
    }
    return row[n];
}

/* Appends " 'NAME'" (comma-separated) to list unless it is there already. */
static void list_name(char *list, size_t size, const char *name)
{
    char quoted[160];
    snprintf(quoted, sizeof(quoted), "'%.140s'", name);
    if (strstr(list, quoted))
        return;
    size_t length = strlen(list);
    snprintf(list + length, size - length, "%s%s", length ? ", " : "", quoted);
}

/* The scene's surface or materials that `name` means (the rule at the top of this file).
 * RAD_ERR_INVALID naming the file when nothing or several names match: `what` says what
 * was looked for ("surface or material"). */
static rad_status find_name(const rad_scene *scene, const char *name, const char *what,
                            name_match *match, rad_error *error)
{
    match->surface = UINT32_MAX;
    match->material = NULL;
    for (int ignore_case = 0; ignore_case <= 1; ignore_case++) {
        char list[512] = "";
        unsigned names = 0;
        for (uint32_t s = 0; s < scene->surface_count; s++)
            if (same_name(scene->surfaces[s].name, name, ignore_case)) {
                match->surface = s;
                names++;
                list_name(list, sizeof(list), scene->surfaces[s].name);
            }
        if (names == 0)
            for (uint32_t m = 0; m < scene->material_count; m++)
                if (same_name(scene->materials[m].name, name, ignore_case) &&
                    (!match->material || strcmp(match->material, scene->materials[m].name))) {
                    match->material = scene->materials[m].name;
                    names++;
                    list_name(list, sizeof(list), match->material);
                }
        if (names == 1)
            return RAD_OK;
        if (names > 1)
            return rad_fail(error, RAD_ERR_INVALID,
                            "no %s '%s' in %s, and %u %s ignoring case: %s; give one of them "
                            "exactly",
                            what, name, scene->source, names,
                            match->surface != UINT32_MAX ? "surfaces" : "materials", list);
    }
    const char *closest = NULL;
    unsigned best = UINT32_MAX;
    for (uint32_t s = 0; s < scene->surface_count; s++) {
        unsigned d = edit_distance(name, scene->surfaces[s].name);
        if (d < best)
            best = d, closest = scene->surfaces[s].name;
    }
    for (uint32_t m = 0; m < scene->material_count; m++) {
        unsigned d = edit_distance(name, scene->materials[m].name);
        if (d < best)
            best = d, closest = scene->materials[m].name;
    }
    if (!closest)
        return rad_fail(error, RAD_ERR_INVALID, "no %s '%s' in %s", what, name, scene->source);
    return rad_fail(error, RAD_ERR_INVALID, "no %s '%s' in %s; did you mean '%s'?", what, name,
                    scene->source, closest);
}

rad_status rad_scene_set_material(rad_scene *scene, const char *name, const rad_rgb *albedo,
                                  const rad_rgb *emission, rad_error *error)
{
    if ((albedo && !rgb_in(albedo, 1)) || (emission && !rgb_in(emission, INFINITY)))
        return rad_fail(error, RAD_ERR_INVALID,
                        "'%s': albedo must be in [0,1] and emission finite and >= 0", name);
    name_match match;
    rad_status status = find_name(scene, name, "surface or material", &match, error);
    if (status != RAD_OK)
        return status;
    if (match.surface != UINT32_MAX) {
        uint32_t s = match.surface;
        const rad_surface *surface = &scene->surfaces[s];
        /* each material of this surface: changed in place when no other surface uses it,
         * else replaced by a changed copy for this surface's triangles */
        uint32_t count = scene->material_count;
        uint8_t *use = rad_alloc_array(count, 1); /* bit 1: used here, bit 2: elsewhere */
        if (!use)
            return rad_fail(error, RAD_ERR_NOMEM, "out of memory");
        for (uint32_t t = 0; t < scene->triangle_count; t++)
            use[scene->triangles[t].material] |= scene->triangles[t].surface == s ? 1 : 2;
        uint32_t first = surface->first_triangle, end = first + surface->triangle_count;
        for (uint32_t m = 0; m < count; m++) {
            if (!(use[m] & 1))
                continue;
            uint32_t target = m;
            if ((use[m] & 2) && (target = copy_material(scene, m)) == UINT32_MAX) {
                free(use);
                return rad_fail(error, RAD_ERR_NOMEM, "out of memory");
            }
            apply(&scene->materials[target], albedo, emission);
            if (target != m) {
                for (uint32_t t = first; t < end; t++)
                    if (scene->triangles[t].material == m)
                        scene->triangles[t].material = target;
                char original[sizeof(scene->materials[m].name)];
                memcpy(original, scene->materials[m].name, sizeof(original));
                snprintf(scene->materials[target].name, sizeof(scene->materials[target].name),
                         "%.60s@%.60s", original, surface->name);
            }
        }
        free(use);
        return RAD_OK;
    }
    /* every material of that name (copy it: applying changes none of the names) */
    char material[sizeof(scene->materials[0].name)];
    snprintf(material, sizeof(material), "%s", match.material);
    for (uint32_t m = 0; m < scene->material_count; m++)
        if (strcmp(scene->materials[m].name, material) == 0)
            apply(&scene->materials[m], albedo, emission);
    return RAD_OK;
}

rad_status rad_scene_set_surface_flags(rad_scene *scene, const char *name, uint32_t flags,
                                       rad_error *error)
{
    name_match match;
    rad_status status = find_name(scene, name, "surface or material", &match, error);
    if (status != RAD_OK)
        return status;
    if (match.surface != UINT32_MAX) {
        scene->surfaces[match.surface].flags |= flags;
        return RAD_OK;
    }
    /* every surface with a triangle of a material of that name */
    for (uint32_t t = 0; t < scene->triangle_count; t++) {
        const rad_triangle *triangle = &scene->triangles[t];
        if (strcmp(scene->materials[triangle->material].name, match.material) == 0)
            scene->surfaces[triangle->surface].flags |= flags;
    }
    return RAD_OK;
}
