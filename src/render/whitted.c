/*
 * whitted.c - Whitted ray tracing with the Phong model (METHOD.md section 1): rad_raytrace.
 *
 * Each camera sample's radiance at the first surface it hits is
 *
 *   I = I_E + K_A I_A + sum over point lights (K_D <N,L> + K_S <V,R>^n) I_L S_L
 *       + direct light of the emitting surfaces (area lights, below) + K_S I_R
 *
 * with K_A = K_D = the albedo Kd, I_E = the emitted radiance Ke (each times its texture's
 * texel at the point, scene/material_at.h), N the front normal of the triangle hit, L and
 * V unit vectors to the light and to the viewer, R = 2 <N,L> N - L, n = the shininess Ns,
 * S_L = 1 when a shadow ray reaches the light, and I_R the radiance along the mirror
 * direction of the incoming ray, followed while K_S > 0 and fewer than max_depth
 * reflections were made. The lobe <V,R>^n counts only where <V,R> > 0 (so n = 0
 * does not light surfaces facing away from the mirror direction).
 *
 * What it is not: a physically based renderer. Point lights have no distance falloff (the
 * classic model: I_L is what reaches every point); the Phong lobe is not energy-normalised;
 * surfaces are one-sided (a back face, and a miss, is black), except two-sided ones
 * (RAD_SURFACE_TWO_SIDED), whose back is shaded as their front with the normal turned
 * towards the viewer, and which emit from both sides.
 *
 * Area lights. Every emitting triangle is part of one area light, sampled `light_samples`
 * times per shading point (emitters_sample: triangle by power, then a point uniformly on
 * it, whose L_e is the emission texel there; the triangle choice is stratified, and the points each triangle gets are a shifted
 * Halton sequence, see shade_direct). There the Phong model is read as the BRDF
 *     f = (K_D + K_S <V,R>^n) / pi
 * integrated against the emitters: each sample q adds
 *     (K_D + K_S <V,R>^n) / pi * L_e cos_surface cos_light / r^2 / pdf_area / light_samples
 * so the diffuse part is exactly the physically based direct-light estimator, and the
 * specular lobe is weighted the same way (unlike the point-light formula it fades with
 * cos_surface; it is not energy-normalised). Lights are one-sided (cos_light > 0) and every
 * sample casts its own shadow ray. Note: a visible emitter also reaches a K_S > 0 surface
 * through the mirror ray K_S I_R, so its highlight is counted by both terms, as in
 * Whitted's model itself; the lobe part is at most K_S times the light's irradiance / pi.
 *
 * Samples per pixel: k x k stratified and jittered (box filter); with one sample the ray
 * goes through the pixel centre exactly, so one-sample images are reproducible by hand.
 *
 * The one idea to read it: the work is a wavefront. A thread takes a row; its camera samples
 * are traced in packets, one batched closest-hit query per bounce; every shading point
 * queues its shadow rays with the radiance they add when unblocked, and the queue is traced
 * in batches. Per sample, contributions are summed in a fixed order and random numbers are
 * hashes of (seed, pixel, sample, bounce), so the image is bitwise the same for any thread
 * count. Nothing is allocated once the rows start.
 */
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/error.h"
#include "core/random.h"
#include "core/tolerance.h"
#include "core/rgb.h"
#include "core/vec3.h"
#include "lights/direct_light.h"
#include "render/camera.h"
#include "lights/emitters.h"
#include "render/progress.h"
#include "scene/material_at.h"
#include "trace/ray.h"

/* Secondary rays leave a surface from a point nudged this far along its normal and ignore
 * hits closer than it (t_near): this fraction of the scene's bounding-box diagonal (scene
 * units; clears the triangle that was hit, whatever the scene's unit) ... */
#define RT_OFFSET_DIAGONAL 1e-5
/* ... plus this fraction of the largest coordinate magnitude (about 8 float ulps: rays are
 * traced in single precision, so a scene far from the origin needs a larger gap). */
#define RT_OFFSET_COORDINATE 1e-6
/* An emitter sample whose direction makes a cosine at most this with either normal lies in
 * that surface's plane (dimensionless; rounding leaves about 1e-16 there): it adds nothing. */
#define RT_GRAZING_COSINE 1e-9
/* A ray whose cosine with the triangle it hit is below this is refined from the tracer's t
 * instead of by intersecting the plane in double precision (dimensionless). */
#define RT_PLANE_COSINE 1e-12

#define MAX_STRATA 1024u          /* k of k x k samples per pixel: 1M samples at most */
#define MAX_LIGHT_SAMPLES 65536u  /* per shading point */

/* Work sizes: camera samples traced together, shadow rays per occlusion query. */
#define PACKET_SAMPLES 1024u
#define SHADOW_BATCH 4096u

/* Stream tags: independent random numbers for the pixel jitter and the light samples. */
#define STREAM_CAMERA 0x63616d657261ull
#define STREAM_LIGHT 0x6c69676874ull

/* A ray alive in the wavefront: where it goes and how much of its radiance reaches the
 * camera sample it belongs to. */
typedef struct rt_path {
    rad_vec3 origin, direction; /* direction is unit length */
    rad_rgb weight;             /* product of K_S over the mirror bounces so far */
    uint32_t sample;            /* index in the packet */
} rt_path;

/* What every thread reads: the scene, its tracer and lights, the resolved options. */
typedef struct rt_context {
    const rad_scene *scene;
    const rad_tracer *tracer;
    const emitter_set *emitters;
    const rad_vec3 *normal;       /* unit front normal of every scene triangle */
    const rad_point_light *lights;
    uint32_t light_count;
    rad_rgb ambient;
    uint32_t light_samples;       /* 0 when the scene has no emitter */
    uint32_t max_depth;
    uint32_t strata;              /* k: k x k samples per pixel */
    uint64_t seed;
    camera_frame frame;
    uint32_t width, height;
    float camera_near;            /* t_near of camera rays */
    double offset;                /* secondary-ray gap, scene units */
    light_set scene_lights;       /* the scene's light sources besides emitters */
    uint32_t sky_samples;         /* directions toward a sky per shading point */
} rt_context;

/* One thread's buffers, allocated before the rows start. */
typedef struct rt_workspace {
    rt_path *paths;
    rad_ray *rays;
    rad_hit *hits;
    rad_rgb *radiance;        /* per packet sample */
    uint64_t packet_first;    /* row sample index of the packet's sample 0 */
    rad_ray *shadow_rays;
    uint8_t *shadow_occluded;
    rad_rgb *shadow_add;      /* radiance the shadow ray adds to its sample when unblocked */
    uint32_t *shadow_sample;
    uint32_t shadow_count;
    rad_rgb *pixel_sum;       /* width: the row's pixel sums */
} rt_workspace;



/* Traces the queued shadow rays and adds what the unblocked ones bring. */
static void flush_shadows(const rt_context *ctx, rt_workspace *ws)
{
    if (ws->shadow_count == 0)
        return;
    rad_tracer_occluded(ctx->tracer, ws->shadow_rays, ws->shadow_count, ws->shadow_occluded);
    for (uint32_t k = 0; k < ws->shadow_count; k++)
        if (!ws->shadow_occluded[k])
            ws->radiance[ws->shadow_sample[k]] =
                rgb_add(ws->radiance[ws->shadow_sample[k]], ws->shadow_add[k]);
    ws->shadow_count = 0;
}

/* Queues a shadow segment from `from` to `to` (both already nudged off their surfaces). */
static void queue_shadow(const rt_context *ctx, rt_workspace *ws, rad_vec3 from, rad_vec3 to,
                         double end_gap, uint32_t sample, rad_rgb add)
{
    if (ws->shadow_count >= SHADOW_BATCH) /* the light sources' rays may have gone past it */
        flush_shadows(ctx, ws);
    uint32_t k = ws->shadow_count++;
    rad_vec3 d = v3_sub(to, from);
    double length = v3_length(d);
    /* t runs over [0,1] along the segment; a segment shorter than the gaps is unblocked
     * (t_near > t_far: nothing can be hit) */
    double t_near = length > 0 ? ctx->offset / length : 1;
    double t_far = length > 0 ? 1 - end_gap / length : 0;
    ray_set(&ws->shadow_rays[k], from, d, t_near, t_far);
    ws->shadow_sample[k] = sample;
    ws->shadow_add[k] = add;
}

/* The Phong lobe <V,R>^n with R = 2 <N,L> N - L; 0 where <V,R> <= 0. */
static double phong_lobe(rad_vec3 N, rad_vec3 L, double NL, rad_vec3 V, double n)
{
    rad_vec3 R = v3_sub(v3_scale(N, 2 * NL), L);
    double c = v3_dot(V, R);
    return c > 0 ? pow(c, n) : 0;
}

static double wrap(double u) { return u < 1 ? u : u - 1; }

/* Queues the direct light at point p (front normal N, viewer direction V) of the surface
 * with material m and, there, albedo `albedo` (K_D, textured), for packet sample `sample`
 * seen with `weight`. */
static void shade_direct(const rt_context *ctx, rt_workspace *ws, const rad_material *m,
                         rad_rgb albedo, uint32_t triangle, rad_vec3 p, rad_vec3 N, rad_vec3 V,
                         rad_rgb weight, uint32_t sample, uint64_t pixel, uint32_t depth)
{
    bool specular = !rgb_is_zero(m->specular);
    rad_vec3 from = v3_add(p, v3_scale(N, ctx->offset));

    for (uint32_t l = 0; l < ctx->light_count; l++) {
        const rad_point_light *light = &ctx->lights[l];
        rad_vec3 D = v3_sub(light->position, p);
        double distance = v3_length(D);
        if (!(distance > 0))
            continue;
        rad_vec3 L = v3_scale(D, 1 / distance);
        double NL = v3_dot(N, L);
        if (NL <= 0)
            continue;
        double lobe = specular ? phong_lobe(N, L, NL, V, m->shininess) : 0;
        rad_rgb bracket = rgb_add(rgb_scale(albedo, NL), rgb_scale(m->specular, lobe));
        rad_rgb add = rgb_mul(rgb_mul(weight, bracket), light->intensity);
        if (!rgb_is_zero(add))
            queue_shadow(ctx, ws, from, light->position, 0, sample, add);
    }

    uint64_t in_pixel = (ws->packet_first + sample) % ((uint64_t)ctx->strata * ctx->strata);
    rad_rng rng = rad_rng_seed(ctx->seed + STREAM_LIGHT, pixel, (in_pixel << 32) | depth);
    const light_set *lights = &ctx->scene_lights;
    if (lights->count) {
        /* the scene's light sources: (K_D + K_S <V,R>^n) / pi times each one's irradiance,
         * one shadow ray per point, spot, luminaire or sun, sky_samples toward a sky */
        uint32_t room = light_set_capacity(lights, LIGHTS_SHARP | LIGHTS_SOFT, ctx->sky_samples);
        if (ws->shadow_count > 0 && ws->shadow_count + room > SHADOW_BATCH)
            flush_shadows(ctx, ws); /* the buffers hold SHADOW_BATCH + room */
        uint32_t first = ws->shadow_count;
        uint32_t count = light_set_rays(lights, LIGHTS_SHARP | LIGHTS_SOFT, p, N, ctx->offset,
                                        (uint32_t)in_pixel, ctx->strata * ctx->strata,
                                        ctx->sky_samples, &rng, &ws->shadow_rays[first],
                                        &ws->shadow_add[first]);
        for (uint32_t q = first; q < first + count; q++) {
            const rad_ray *ray = &ws->shadow_rays[q];
            rad_vec3 L = v3_normalize(v3(ray->direction[0], ray->direction[1], ray->direction[2]));
            double NL = v3_dot(N, L);
            double lobe = specular && NL > 0 ? phong_lobe(N, L, NL, V, m->shininess) : 0;
            rad_rgb brdf = rgb_scale(rgb_add(albedo, rgb_scale(m->specular, lobe)), 1 / RAD_PI);
            ws->shadow_add[q] = rgb_mul(rgb_mul(weight, brdf), ws->shadow_add[q]);
            ws->shadow_sample[q] = sample;
        }
        ws->shadow_count += count;
    }

    uint32_t n = ctx->light_samples;
    if (n == 0)
        return;
    /* Triangle choice stratified: u0 in stratum i, so each triangle gets a contiguous block
     * of samples; inside a block, the point is the block's j-th Halton point (bases 2, 3),
     * shifted by one random offset per shading point (Cranley-Patterson), so each sample
     * is uniform on its triangle and a block covers its triangle evenly. */
    double shift1 = rad_rng_uniform(&rng), shift2 = rad_rng_uniform(&rng);
    uint32_t block_triangle = RAD_NO_HIT, j = 0;
    for (uint32_t i = 0; i < n; i++, j++) {
        double u0 = (i + rad_rng_uniform(&rng)) / n;
        emitter_sample es;
        emitters_sample(ctx->emitters, ctx->scene, u0, wrap(rad_radical_inverse(j, 2) + shift1),
                        wrap(emitters_halton3(ctx->emitters, j) + shift2), &es);
        if (es.triangle != block_triangle) { /* a new block: start its sequence */
            block_triangle = es.triangle;
            j = 0;
            emitters_sample(ctx->emitters, ctx->scene, u0, shift1, shift2, &es);
        }
        if (es.triangle == triangle)
            continue;
        rad_vec3 D = v3_sub(es.point, p);
        double r2 = v3_dot(D, D);
        if (!(r2 > 0))
            continue;
        rad_vec3 L = v3_scale(D, 1 / sqrt(r2));
        rad_vec3 light_normal;
        double cos_surface = v3_dot(N, L), cos_light = emitter_cosine(&es, L, &light_normal);
        if (cos_surface <= RT_GRAZING_COSINE || cos_light <= RT_GRAZING_COSINE)
            continue;
        double g = cos_surface * cos_light / (RAD_PI * r2 * es.pdf_area * n);
        double lobe = specular ? phong_lobe(N, L, cos_surface, V, m->shininess) : 0;
        rad_rgb brdf = rgb_add(albedo, rgb_scale(m->specular, lobe)); /* times pi */
        rad_rgb add = rgb_mul(rgb_mul(weight, brdf), rgb_scale(es.radiance, g));
        if (rgb_is_zero(add))
            continue;
        rad_vec3 to = v3_add(es.point, v3_scale(light_normal, ctx->offset));
        queue_shadow(ctx, ws, from, to, ctx->offset, sample, add);
    }
}

/* Traces the packet's paths bounce by bounce; radiance[] receives each sample's value. */
static void trace_packet(const rt_context *ctx, rt_workspace *ws, uint32_t count, uint32_t y)
{
    const rad_scene *scene = ctx->scene;
    uint32_t spp = ctx->strata * ctx->strata;
    for (uint32_t depth = 0; count > 0; depth++) {
        for (uint32_t i = 0; i < count; i++) {
            double t_near = depth == 0 ? ctx->camera_near : ctx->offset;
            ray_set(&ws->rays[i], ws->paths[i].origin, ws->paths[i].direction, t_near, INFINITY);
        }
        rad_tracer_intersect(ctx->tracer, ws->rays, count, ws->hits);
        uint32_t alive = 0;
        for (uint32_t i = 0; i < count; i++) {
            const rad_hit *hit = &ws->hits[i];
            if (hit->triangle == RAD_NO_HIT && ctx->scene_lights.has_sky) {
                /* the sky (or environment) behind open geometry */
                rt_path *gone = &ws->paths[i];
                ws->radiance[gone->sample] = rgb_add(
                    ws->radiance[gone->sample],
                    rgb_mul(gone->weight, light_set_sky_radiance(&ctx->scene_lights, gone->direction)));
                continue;
            }
            if (hit->triangle == RAD_NO_HIT ||
                (!hit->front && !triangle_two_sided(scene, hit->triangle)))
                continue; /* black: a miss, or the back of a one-sided surface */
            rt_path path = ws->paths[i];
            const rad_triangle *tri = &scene->triangles[hit->triangle];
            const rad_material *m = &scene->materials[tri->material];
            /* a two-sided surface's back: shaded as a front facing the viewer */
            rad_vec3 N = hit->front ? ctx->normal[hit->triangle]
                                    : v3_scale(ctx->normal[hit->triangle], -1);
            rad_vec3 d = path.direction;
            /* the hit point in double precision: the ray meets the triangle's plane */
            double dn = v3_dot(d, N);
            double t = fabs(dn) > RT_PLANE_COSINE
                           ? v3_dot(v3_sub(scene->positions[tri->vertex[0]], path.origin), N) / dn
                           : hit->t;
            rad_vec3 p = v3_add(path.origin, v3_scale(d, t));
            rad_vec3 V = v3_scale(d, -1);

            /* K_A = K_D = the albedo at the point, I_E its emitted radiance (textures
             * applied) */
            rad_rgb albedo = material_albedo_at(scene, hit->triangle, hit->u, hit->v);
            rad_rgb emitted = material_emission_at(scene, hit->triangle, hit->u, hit->v);
            rad_rgb local = rgb_add(emitted, rgb_mul(albedo, ctx->ambient));
            ws->radiance[path.sample] =
                rgb_add(ws->radiance[path.sample], rgb_mul(path.weight, local));
            uint64_t pixel = (uint64_t)y * ctx->width + (ws->packet_first + path.sample) / spp;
            shade_direct(ctx, ws, m, albedo, hit->triangle, p, N, V, path.weight, path.sample,
                         pixel, depth);

            if (depth < ctx->max_depth && !rgb_is_zero(m->specular)) {
                rt_path next = path; /* alive <= i: overwrites only finished paths */
                next.origin = v3_add(p, v3_scale(N, ctx->offset));
                next.direction = v3_normalize(v3_sub(d, v3_scale(N, 2 * dn)));
                next.weight = rgb_mul(path.weight, m->specular);
                ws->paths[alive++] = next;
            }
        }
        count = alive;
    }
    flush_shadows(ctx, ws);
}

/* Renders row y into the image. */
static void trace_row(const rt_context *ctx, rt_workspace *ws, uint32_t y, float *row)
{
    uint32_t k = ctx->strata, spp = k * k;
    uint64_t total = (uint64_t)ctx->width * spp;
    memset(ws->pixel_sum, 0, ctx->width * sizeof(*ws->pixel_sum));
    for (uint64_t first = 0; first < total; first += PACKET_SAMPLES) {
        uint32_t count = (uint32_t)(total - first < PACKET_SAMPLES ? total - first : PACKET_SAMPLES);
        ws->packet_first = first;
        for (uint32_t i = 0; i < count; i++) {
            uint64_t j = first + i;
            uint32_t x = (uint32_t)(j / spp), s = (uint32_t)(j % spp);
            double px = x + 0.5, py = y + 0.5;
            if (k > 1) {
                rad_rng rng = rad_rng_seed(ctx->seed + STREAM_CAMERA, (uint64_t)y * ctx->width + x, s);
                px = x + ((s % k) + rad_rng_uniform(&rng)) / k;
                py = y + ((s / k) + rad_rng_uniform(&rng)) / k;
            }
            rt_path *path = &ws->paths[i];
            path->origin = ctx->frame.eye;
            path->direction =
                v3_normalize(camera_direction(&ctx->frame, px, py, ctx->width, ctx->height));
            path->weight = (rad_rgb){1, 1, 1};
            path->sample = i;
            ws->radiance[i] = (rad_rgb){0, 0, 0};
        }
        trace_packet(ctx, ws, count, y);
        for (uint32_t i = 0; i < count; i++) {
            uint32_t x = (uint32_t)((first + i) / spp);
            ws->pixel_sum[x] = rgb_add(ws->pixel_sum[x], ws->radiance[i]);
        }
    }
    for (uint32_t x = 0; x < ctx->width; x++) {
        row[3 * x + 0] = (float)(ws->pixel_sum[x].r / spp);
        row[3 * x + 1] = (float)(ws->pixel_sum[x].g / spp);
        row[3 * x + 2] = (float)(ws->pixel_sum[x].b / spp);
    }
}

static void workspace_free(rt_workspace *ws)
{
    free(ws->paths);
    free(ws->rays);
    free(ws->hits);
    free(ws->radiance);
    free(ws->shadow_rays);
    free(ws->shadow_occluded);
    free(ws->shadow_add);
    free(ws->shadow_sample);
    free(ws->pixel_sum);
}

static bool workspace_alloc(rt_workspace *ws, uint32_t width, uint32_t shadow_capacity)
{
    memset(ws, 0, sizeof(*ws));
    ws->paths = rad_alloc_array(PACKET_SAMPLES, sizeof(*ws->paths));
    ws->rays = rad_alloc_array(PACKET_SAMPLES, sizeof(*ws->rays));
    ws->hits = rad_alloc_array(PACKET_SAMPLES, sizeof(*ws->hits));
    ws->radiance = rad_alloc_array(PACKET_SAMPLES, sizeof(*ws->radiance));
    ws->shadow_rays = rad_alloc_array(shadow_capacity, sizeof(*ws->shadow_rays));
    ws->shadow_occluded = rad_alloc_array(shadow_capacity, sizeof(*ws->shadow_occluded));
    ws->shadow_add = rad_alloc_array(shadow_capacity, sizeof(*ws->shadow_add));
    ws->shadow_sample = rad_alloc_array(shadow_capacity, sizeof(*ws->shadow_sample));
    ws->pixel_sum = rad_alloc_array(width, sizeof(*ws->pixel_sum));
    return ws->paths && ws->rays && ws->hits && ws->radiance && ws->shadow_rays &&
           ws->shadow_occluded && ws->shadow_add && ws->shadow_sample &&
           ws->pixel_sum;
}

/* Checks what the caller gave; the scene itself is valid by construction. */
static rad_status check_options(const rad_raytrace_options *o, rad_error *error)
{
    if (o->threads < 0)
        return rad_fail(error, RAD_ERR_INVALID, "raytrace: threads must not be negative");
    if (o->light_count > 0 && !o->lights)
        return rad_fail(error, RAD_ERR_INVALID, "raytrace: %u lights but no light array",
                        o->light_count);
    for (uint32_t l = 0; l < o->light_count; l++) {
        if (!v3_is_finite(o->lights[l].position))
            return rad_fail(error, RAD_ERR_INVALID, "raytrace: light %u: position not finite", l);
        if (!rgb_valid(o->lights[l].intensity))
            return rad_fail(error, RAD_ERR_INVALID,
                            "raytrace: light %u: intensity must be finite and not negative", l);
    }
    if (!rgb_valid(o->ambient))
        return rad_fail(error, RAD_ERR_INVALID,
                        "raytrace: ambient must be finite and not negative");
    if (o->light_samples > MAX_LIGHT_SAMPLES)
        return rad_fail(error, RAD_ERR_INVALID, "raytrace: light_samples %u above the %u allowed",
                        o->light_samples, MAX_LIGHT_SAMPLES);
    return RAD_OK;
}

rad_status rad_raytrace(const rad_scene *scene, const rad_camera *camera,
                        const rad_raytrace_options *options, rad_image *image,
                        rad_error *error)
{
    rad_raytrace_options defaults = {0};
    if (!options)
        options = &defaults;
    rad_status status = check_options(options, error);
    if (status != RAD_OK)
        return status;

    rt_context ctx;
    memset(&ctx, 0, sizeof(ctx));
    ctx.width = image->width;
    ctx.height = image->height;
    status = camera_frame_make(camera, ctx.width, ctx.height, &ctx.frame, error);
    if (status != RAD_OK)
        return status;
    uint32_t spp = options->samples_per_pixel ? options->samples_per_pixel
                                              : RAD_DEFAULT_RAYTRACE_SPP;
    long k = lround(sqrt((double)spp));
    ctx.strata = k < 1 ? 1 : k > (long)MAX_STRATA ? MAX_STRATA : (uint32_t)k;
    ctx.max_depth = options->max_depth ? options->max_depth : RAD_DEFAULT_MAX_DEPTH;
    ctx.scene = scene;
    ctx.lights = options->lights;
    ctx.light_count = options->light_count;
    ctx.ambient = options->ambient;
    light_set_init(&ctx.scene_lights, scene);
    ctx.sky_samples = options->light_samples ? options->light_samples : RAD_DEFAULT_LIGHT_SAMPLES;
    ctx.seed = options->seed;
    int threads = options->threads > 0 ? options->threads : omp_get_max_threads();

    rad_vec3 lo, hi;
    rad_scene_bounds(scene, &lo, &hi);
    double diagonal = v3_length(v3_sub(hi, lo));
    double largest = fmax(fmax(fmax(fabs(lo.x), fabs(hi.x)), fmax(fabs(lo.y), fabs(hi.y))),
                          fmax(fabs(lo.z), fabs(hi.z)));
    ctx.offset = RT_OFFSET_DIAGONAL * diagonal + RT_OFFSET_COORDINATE * largest;
    ctx.camera_near = (float)(RAD_CAMERA_NEAR * diagonal);

    rad_tracer *tracer = NULL;
    emitter_set emitters;
    memset(&emitters, 0, sizeof(emitters));
    rad_vec3 *normal = NULL;
    rt_workspace *workspaces = NULL;
    int workspaces_made = 0;

    status = rad_tracer_create_for_scene(RAD_TRACER_EMBREE, scene, &tracer, error);
    if (status != RAD_OK)
        goto done;
    status = emitters_build(scene, &emitters, error);
    if (status != RAD_OK)
        goto done;
    if (emitters.count > 0) {
        ctx.light_samples = options->light_samples ? options->light_samples
                                                   : RAD_DEFAULT_LIGHT_SAMPLES;
    }
    normal = rad_alloc_array(scene->triangle_count, sizeof(*normal));
    workspaces = rad_alloc_array((size_t)threads, sizeof(*workspaces));
    if (!normal || !workspaces)
        goto nomem;
    for (uint32_t t = 0; t < scene->triangle_count; t++) {
        const uint32_t *v = scene->triangles[t].vertex;
        rad_vec3 a = scene->positions[v[0]], b = scene->positions[v[1]],
                 c = scene->positions[v[2]];
        normal[t] = v3_normalize(v3_cross(v3_sub(b, a), v3_sub(c, a)));
    }
    /* a batch, and room for one shading point's light-source rays past it */
    uint32_t room = light_set_capacity(&ctx.scene_lights, LIGHTS_SHARP | LIGHTS_SOFT,
                                       ctx.sky_samples);
    for (; workspaces_made < threads; workspaces_made++)
        if (!workspace_alloc(&workspaces[workspaces_made], ctx.width, SHADOW_BATCH + room)) {
            workspaces_made++; /* so that its partial buffers are freed too */
            goto nomem;
        }
    ctx.tracer = tracer;
    ctx.emitters = &emitters;
    ctx.normal = normal;

    render_progress progress =
        render_progress_start(options->progress, options->progress_user, "raytrace", ctx.height);
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (uint32_t y = 0; y < ctx.height; y++) {
        trace_row(&ctx, &workspaces[omp_get_thread_num()], y,
                  &image->rgb[(size_t)y * ctx.width * 3]);
        render_progress_step(&progress);
    }
    render_progress_finish(&progress);
    goto done;
nomem:
    status = rad_fail(error, RAD_ERR_NOMEM, "out of memory for ray tracing");
done:
    for (int w = 0; w < workspaces_made; w++)
        workspace_free(&workspaces[w]);
    free(workspaces);
    free(normal);
    emitters_free(&emitters);
    rad_tracer_destroy(tracer);
    return status;
}
