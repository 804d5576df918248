/*
 * scene_lights.c - the scene's light sources besides emissive surfaces: adding one (checked
 * once here, so every renderer and solver can trust them), the scene's north, and freeing
 * them with the scene.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/error.h"
#include "core/vec3.h"
#include "lights/scene_lights.h"
#include "radiosity.h"

static const char *type_name(rad_light_type type)
{
    switch (type) {
    case RAD_LIGHT_POINT:
        return "point";
    case RAD_LIGHT_SPOT:
        return "spot";
    case RAD_LIGHT_DIRECTIONAL:
        return "sun";
    case RAD_LIGHT_SKY:
        return "sky";
    case RAD_LIGHT_ENVIRONMENT:
        return "environment";
    case RAD_LIGHT_LUMINAIRE:
        return "luminaire";
    }
    return "light";
}

const char *rad_light_type_name(rad_light_type type) { return type_name(type); }

void scene_lights_free(rad_scene *scene)
{
    for (uint32_t l = 0; l < scene->light_count; l++) {
        rad_photometry_destroy(scene->lights[l].photometry);
        rad_image_destroy(scene->lights[l].environment);
    }
    free(scene->lights);
    scene->lights = NULL;
    scene->light_count = 0;
}

static bool rgb_ok(rad_rgb c)
{
    return isfinite(c.r) && isfinite(c.g) && isfinite(c.b) && c.r >= 0 && c.g >= 0 && c.b >= 0;
}

static bool needs_direction(rad_light_type type)
{
    return type == RAD_LIGHT_SPOT || type == RAD_LIGHT_DIRECTIONAL ||
           type == RAD_LIGHT_LUMINAIRE;
}

/* The light made ready for use: directions unit length, a luminaire's reference
 * perpendicular to its nadir. false with a message when it cannot be used. */
static bool check_light(const rad_scene *scene, rad_light *l, rad_error *error,
                        rad_status *status)
{
    const char *what = type_name(l->type);
    const char *name = l->name[0] ? l->name : what;
    *status = RAD_ERR_INVALID;
    if (l->type < RAD_LIGHT_POINT || l->type > RAD_LIGHT_LUMINAIRE) {
        rad_fail(error, RAD_ERR_INVALID, "light '%s': unknown type %d", name, (int)l->type);
        return false;
    }
    if (!v3_is_finite(l->position) || !v3_is_finite(l->direction) ||
        !v3_is_finite(l->reference) || !isfinite(l->inner_degrees) ||
        !isfinite(l->outer_degrees) || !isfinite(l->angular_diameter_degrees) ||
        !isfinite(l->rotate_degrees)) {
        rad_fail(error, RAD_ERR_INVALID, "%s light '%s': a value is not a finite number", what,
                 name);
        return false;
    }
    if (!rgb_ok(l->intensity)) {
        rad_fail(error, RAD_ERR_INVALID,
                 "%s light '%s': intensity (%g, %g, %g) must be finite and not negative", what,
                 name, l->intensity.r, l->intensity.g, l->intensity.b);
        return false;
    }
    bool sky_with_sun = l->type == RAD_LIGHT_SKY && l->sky == RAD_SKY_CIE_CLEAR;
    if (needs_direction(l->type) || sky_with_sun) {
        double length = v3_length(l->direction);
        if (!(length > 0)) {
            rad_fail(error, RAD_ERR_INVALID, "%s light '%s': its direction is zero", what, name);
            return false;
        }
        l->direction = v3_scale(l->direction, 1 / length);
    }
    if (l->type == RAD_LIGHT_SPOT &&
        !(l->inner_degrees >= 0 && l->inner_degrees <= l->outer_degrees &&
          l->outer_degrees <= 90 && l->outer_degrees > 0)) {
        rad_fail(error, RAD_ERR_INVALID,
                 "spot light '%s': cone half-angles inner %g and outer %g degrees must satisfy "
                 "0 <= inner <= outer <= 90 and outer > 0",
                 name, l->inner_degrees, l->outer_degrees);
        return false;
    }
    if (l->type == RAD_LIGHT_DIRECTIONAL &&
        !(l->angular_diameter_degrees >= 0 && l->angular_diameter_degrees < 20)) {
        rad_fail(error, RAD_ERR_INVALID,
                 "sun '%s': angular diameter %g degrees is outside [0, 20) (the sun's is 0.53)",
                 name, l->angular_diameter_degrees);
        return false;
    }
    if (l->type == RAD_LIGHT_SKY &&
        !(l->sky == RAD_SKY_UNIFORM || l->sky == RAD_SKY_CIE_OVERCAST || sky_with_sun)) {
        rad_fail(error, RAD_ERR_INVALID, "sky '%s': unknown sky model %d", name, (int)l->sky);
        return false;
    }
    if (l->type == RAD_LIGHT_LUMINAIRE) {
        if (!l->photometry) {
            rad_fail(error, RAD_ERR_INVALID, "luminaire '%s' has no photometric data", name);
            return false;
        }
        if (l->photometry->photometric_type != 1) {
            rad_fail(error, RAD_ERR_UNSUPPORTED,
                     "luminaire '%s': %s is photometric type %s; only type C (the usual, 1) "
                     "is supported as a light",
                     name, l->photometry->source, l->photometry->photometric_type == 2 ? "B" : "A");
            *status = RAD_ERR_UNSUPPORTED;
            return false;
        }
        rad_vec3 d = l->direction, r = l->reference;
        r = v3_sub(r, v3_scale(d, v3_dot(r, d)));
        if (!(v3_length(r) > 1e-6 * (v3_length(l->reference) + 1))) {
            /* horizontal angle 0 along the scene's north, or east when the nadir is north */
            rad_vec3 north = rad_scene_north(scene);
            r = v3_sub(north, v3_scale(d, v3_dot(north, d)));
            if (!(v3_length(r) > 1e-6)) {
                rad_vec3 east = v3_cross(north, scene->up);
                r = v3_sub(east, v3_scale(d, v3_dot(east, d)));
            }
        }
        l->reference = v3_normalize(r);
    }
    if (l->type == RAD_LIGHT_ENVIRONMENT) {
        const rad_image *map = l->environment;
        if (!map || map->width == 0 || map->width != 2 * map->height) {
            rad_fail(error, RAD_ERR_INVALID,
                     "environment '%s': %s (an equirectangular map is twice as wide as high)",
                     name, map ? "the map is not 2:1" : "no map");
            return false;
        }
    }
    *status = RAD_OK;
    return true;
}

rad_status rad_scene_add_light(rad_scene *scene, const rad_light *light, rad_error *error)
{
    rad_light copy = *light;
    copy.name[sizeof(copy.name) - 1] = '\0';
    rad_status status;
    if (!check_light(scene, &copy, error, &status))
        return status;
    rad_light *grown =
        rad_resize_array(scene->lights, (size_t)scene->light_count + 1, sizeof(*grown));
    if (!grown)
        return rad_fail(error, RAD_ERR_NOMEM, "out of memory for a light");
    scene->lights = grown;
    scene->lights[scene->light_count++] = copy;
    return RAD_OK;
}

rad_vec3 rad_scene_north(const rad_scene *scene)
{
    rad_vec3 up = scene->up;
    if (!(v3_length(up) > 0))
        up = v3(0, 1, 0);
    up = v3_normalize(up);
    rad_vec3 n = scene->north;
    n = v3_sub(n, v3_scale(up, v3_dot(n, up)));
    if (v3_length(n) > 1e-9)
        return v3_normalize(n);
    /* y up: north is -z (east is then +x); z up: north is +y (east +x); otherwise the
     * axis after up's, made perpendicular */
    int axis = fabs(up.y) >= fabs(up.x) && fabs(up.y) >= fabs(up.z) ? 1
               : fabs(up.z) >= fabs(up.x)                           ? 2
                                                                    : 0;
    rad_vec3 guess = axis == 1 ? v3(0, 0, -up.y) : axis == 2 ? v3(0, up.z, 0) : v3(0, 0, 1);
    n = v3_sub(guess, v3_scale(up, v3_dot(guess, up)));
    return v3_normalize(n);
}
