/*
 * direct_light.c - direct light from the scene's light sources at a point (direct_light.h).
 *
 * Irradiance per source, x the receiving point, n its normal, w the unit direction from x
 * toward the source, m metres per scene unit:
 *   point       E = I cos(n, w) / (r m)^2
 *   spot        the same times glTF's cone falloff t^2, t = clamp((cos a - cos outer) /
 *               (cos inner - cos outer), 0, 1), a the angle between -w and the spot's axis
 *   luminaire   the same with I = the photometric web's candela toward -w (vertical angle
 *               from the nadir, horizontal counter-clockwise from the reference seen from
 *               above) times the light's factor
 *   sun         E = E_n cos(n, w), w drawn uniformly over the disk's solid angle
 *   sky         E = integral over the hemisphere of L(w) cos dw, estimated with
 *               cosine-weighted stratified directions: pi L(w_k) / K each
 */
#include <math.h>

#include "core/hemisphere.h"
#include "core/rgb.h"
#include "core/tolerance.h"
#include "core/vec3.h"
#include "lights/direct_light.h"
#include "lights/environment_map.h"
#include "lights/sky_model.h"
#include "trace/ray.h"

static bool is_sharp(rad_light_type type)
{
    return type == RAD_LIGHT_POINT || type == RAD_LIGHT_SPOT || type == RAD_LIGHT_LUMINAIRE ||
           type == RAD_LIGHT_DIRECTIONAL;
}

void light_set_init(light_set *set, const rad_scene *scene)
{
    *set = (light_set){0};
    set->scene = scene;
    set->lights = scene->lights;
    set->count = scene->light_count;
    set->metres = scene->unit_metres > 0 ? scene->unit_metres : 1;
    set->up = v3_length(scene->up) > 0 ? v3_normalize(scene->up) : v3(0, 1, 0);
    set->north = rad_scene_north(scene);
    set->east = v3_cross(set->north, set->up);
    rad_vec3 lo, hi;
    rad_scene_bounds(scene, &lo, &hi);
    double diagonal = scene->position_count ? v3_length(v3_sub(hi, lo)) : 1;
    double largest = fmax(fmax(fmax(fabs(lo.x), fabs(hi.x)), fmax(fabs(lo.y), fabs(hi.y))),
                          fmax(fabs(lo.z), fabs(hi.z)));
    set->leave = RAD_SURFACE_LEAVE_DIAGONAL * diagonal + RAD_SURFACE_LEAVE_COORDINATE * largest;
    for (uint32_t l = 0; l < set->count; l++) {
        if (is_sharp(set->lights[l].type))
            set->sharp_count++;
        else
            set->has_sky = true;
    }
}

uint32_t light_set_capacity(const light_set *set, unsigned which, uint32_t sky_rays)
{
    uint32_t count = (which & LIGHTS_SHARP) ? set->sharp_count : 0;
    if ((which & LIGHTS_SOFT) && set->has_sky)
        count += sky_rays;
    return count;
}

/* Stratum `s` of a k x k grid over [0,1)^2, jittered. */
static void stratum(uint32_t s, uint32_t k, rad_rng *rng, double *u1, double *u2)
{
    *u1 = ((s % k) + rad_rng_uniform(rng)) / k;
    *u2 = (((s / k) % k) + rad_rng_uniform(rng)) / k;
}

static uint32_t grid_side(uint32_t count)
{
    uint32_t k = (uint32_t)floor(sqrt((double)count));
    return k < 1 ? 1 : k;
}

/* Intensity (cd, per channel) of a point-like light toward `toward` (unit, from the light). */
static rad_rgb intensity_toward(const rad_light *light, rad_vec3 toward)
{
    switch (light->type) {
    case RAD_LIGHT_SPOT: {
        double cos_a = v3_dot(toward, light->direction);
        double cos_outer = cos(light->outer_degrees * (RAD_PI / 180));
        double cos_inner = cos(light->inner_degrees * (RAD_PI / 180));
        double t;
        if (cos_inner - cos_outer > 1e-12)
            t = fmin(fmax((cos_a - cos_outer) / (cos_inner - cos_outer), 0), 1);
        else
            t = cos_a >= cos_outer ? 1 : 0;
        return rgb_scale(light->intensity, t * t);
    }
    case RAD_LIGHT_LUMINAIRE: {
        rad_vec3 nadir = light->direction, x = light->reference;
        rad_vec3 y = v3_cross(v3_scale(nadir, -1), x);
        double vertical = acos(fmin(fmax(v3_dot(toward, nadir), -1), 1)) * (180 / RAD_PI);
        double horizontal = atan2(v3_dot(toward, y), v3_dot(toward, x)) * (180 / RAD_PI);
        if (horizontal < 0)
            horizontal += 360;
        double candela = rad_photometry_candela(light->photometry, vertical, horizontal);
        return rgb_scale(light->intensity, candela);
    }
    default:
        return light->intensity;
    }
}

/* The sky's luminance per channel toward unit `w`, or 0 below the horizon. */
static rad_rgb sky_radiance(const light_set *set, const rad_light *light, rad_vec3 w)
{
    double sin_h = v3_dot(w, set->up);
    if (light->type == RAD_LIGHT_SKY) {
        if (!(sin_h > 0))
            return (rad_rgb){0, 0, 0};
        double elevation = asin(fmin(sin_h, 1));
        double gamma = 0, sun_elevation = 0;
        if (light->sky == RAD_SKY_CIE_CLEAR) {
            rad_vec3 to_sun = v3_scale(light->direction, -1);
            gamma = acos(fmin(fmax(v3_dot(w, to_sun), -1), 1));
            sun_elevation = asin(fmin(fmax(v3_dot(to_sun, set->up), -1), 1));
        }
        return rgb_scale(light->intensity,
                         rad_sky_relative_luminance(light->sky, elevation, gamma, sun_elevation));
    }
    if (light->type == RAD_LIGHT_ENVIRONMENT) {
        double azimuth, elevation;
        sky_angles(w, set->up, set->north, light->rotate_degrees, &azimuth, &elevation);
        return rgb_mul(light->intensity, environment_radiance(light->environment, azimuth, elevation));
    }
    return (rad_rgb){0, 0, 0};
}

rad_rgb light_set_sky_radiance(const light_set *set, rad_vec3 direction)
{
    rad_rgb sum = {0, 0, 0};
    if (!set->has_sky)
        return sum;
    for (uint32_t l = 0; l < set->count; l++)
        if (!is_sharp(set->lights[l].type))
            rgb_add_to(&sum, sky_radiance(set, &set->lights[l], direction));
    return sum;
}

uint32_t light_set_rays(const light_set *set, unsigned which, rad_vec3 x, rad_vec3 n,
                        double leave, uint32_t sample, uint32_t sample_count,
                        uint32_t sky_rays, rad_rng *rng, rad_ray *rays, rad_rgb *irradiance)
{
    rad_vec3 origin = v3_add(x, v3_scale(n, leave));
    uint32_t count = 0;
    if (which & LIGHTS_SHARP)
        for (uint32_t l = 0; l < set->count; l++) {
            const rad_light *light = &set->lights[l];
            if (!is_sharp(light->type))
                continue;
            if (light->type == RAD_LIGHT_DIRECTIONAL) {
                rad_vec3 w = v3_scale(light->direction, -1);
                double half = 0.5 * light->angular_diameter_degrees * (RAD_PI / 180);
                if (half > 0) {
                    double u1, u2;
                    stratum(sample, grid_side(sample_count), rng, &u1, &u2);
                    double cos_t = 1 - u1 * (1 - cos(half));
                    double sin_t = sqrt(fmax(0, 1 - cos_t * cos_t)), phi = 2 * RAD_PI * u2;
                    rad_vec3 a, b;
                    hemisphere_frame(w, &a, &b);
                    w = v3_add(v3_scale(w, cos_t), v3_add(v3_scale(a, sin_t * cos(phi)),
                                                          v3_scale(b, sin_t * sin(phi))));
                }
                double cos_n = v3_dot(n, w);
                if (!(cos_n > 0))
                    continue;
                irradiance[count] = rgb_scale(light->intensity, cos_n);
                ray_set(&rays[count], origin, w, 0, INFINITY);
                count++;
                continue;
            }
            /* the irradiance at x itself (the shadow ray leaves from the offset origin):
             * measured from the origin, r and the spot's falloff would move by the offset,
             * 1e-4 of the irradiance near a spot's rim (test_lights_matrix.c, Whitted) */
            rad_vec3 to_light = v3_sub(light->position, x);
            double r = v3_length(to_light);
            if (!(r > 0))
                continue;
            rad_vec3 w = v3_scale(to_light, 1 / r);
            double cos_n = v3_dot(n, w);
            if (!(cos_n > 0))
                continue;
            rad_rgb intensity = intensity_toward(light, v3_scale(w, -1));
            if (rgb_is_zero(intensity))
                continue;
            double metres = r * set->metres;
            irradiance[count] = rgb_scale(intensity, cos_n / (metres * metres));
            ray_segment(&rays[count], origin, light->position);
            count++;
        }
    if ((which & LIGHTS_SOFT) && set->has_sky && sky_rays > 0) {
        rad_vec3 a, b;
        hemisphere_frame(n, &a, &b);
        /* one direction: stratum `sample` of the caller's samples; several: stratified
         * among themselves (the first k^2), with a random turn per call */
        uint32_t k = sky_rays == 1 ? grid_side(sample_count) : grid_side(sky_rays);
        double turn = sky_rays == 1 ? 0 : 2 * RAD_PI * rad_rng_uniform(rng);
        for (uint32_t j = 0; j < sky_rays; j++) {
            double u1, u2;
            if (sky_rays == 1 && sample < k * k)
                stratum(sample, k, rng, &u1, &u2);
            else if (sky_rays > 1 && j < k * k)
                stratum(j, k, rng, &u1, &u2);
            else {
                u1 = rad_rng_uniform(rng);
                u2 = rad_rng_uniform(rng);
            }
            rad_vec3 w = cosine_direction(n, a, b, u1, u2, turn, NULL);
            rad_rgb L = light_set_sky_radiance(set, w);
            if (rgb_is_zero(L))
                continue;
            irradiance[count] = rgb_scale(L, RAD_PI / sky_rays);
            ray_set(&rays[count], origin, w, 0, INFINITY);
            count++;
        }
    }
    return count;
}
