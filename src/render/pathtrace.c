/*
 * pathtrace.c - the Monte-Carlo reference: unbiased path tracing of Lambertian scenes.
 *
 * What it estimates: the radiance L seen through each pixel (box filter), for one-sided (or
 * two-sided: RAD_SURFACE_TWO_SIDED, both sides alike) surfaces with albedo Kd and emitted
 * radiance Ke, the same model radiosity solves, each times its texture's texel at the point
 * (scene/material_at.h: albedo at every path vertex, emission seen by every ray and at
 * every light sample), lit by emissive surfaces and by the scene's light sources (rad_light:
 * point, spot, luminaire and sun by next-event estimation, one shadow ray each per
 * vertex; sky and environment seen by the rays that leave the scene). What it is not: a
 * general renderer (no specular).
 *
 * The one idea needed to read it: the image is cut into TILE x TILE tiles, and each tile is
 * traced as a sequence of WAVES. A wave holds SAMPLES_PER_WAVE samples of every pixel of
 * the tile, one path each; all live paths of the wave extend together, so every bounce is
 * one batched closest-hit query followed by one batched shadow query (next-event
 * estimation). Each path draws its random numbers from its own generator seeded by
 * (seed, pixel, sample), and a tile's results are summed in sample order, so the image is
 * bitwise the same for any thread count and any tile schedule. Over several MPI ranks the
 * tiles are shared by estimated cost (a few camera rays per tile: a tile of sky is cheap)
 * and rank 0 gathers them (parallel/image_tiles.h): the same image, bitwise.
 *
 * Per path vertex: a miss or the back of a one-sided surface ends the path (the back of a
 * two-sided one is its front turned towards the ray, emitting too); emission is
 * added with weight 1 on the camera ray and with the power-heuristic MIS weight against
 * light sampling on BSDF-sampled rays; next-event estimation samples a point on the
 * emitters (power-proportional by their mean emission, the sample's radiance the texel
 * at its point, src/lights/emitters.h) and weights it by the same heuristic; the bounce is cosine-weighted around the front normal (throughput *= Kd);
 * Russian roulette starts after RR_START_BOUNCES bounces.
 */
#include <float.h>
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
#include "parallel/image_tiles.h"
#include "parallel/partition.h"
#include "parallel/ranks.h"
#include "render/camera.h"
#include "lights/emitters.h"
#include "render/progress.h"
#include "scene/material_at.h"
#include "trace/ray.h"

/* Tiles are TILE x TILE pixels: the unit of parallel work (dynamic schedule). */
#define TILE 16u

/* Samples of every tile pixel traced together: 4 x 256 = 1024 paths per wave, enough rays
 * per tracer call for full speed while the wave's state stays in cache. */
#define SAMPLES_PER_WAVE 4u
#define WAVE_PATHS (TILE * TILE * SAMPLES_PER_WAVE)


/* Secondary rays start this far in front of the surface, along its normal, and shadow rays
 * stop this far short of the light: a fraction of the scene's bounding-box diagonal
 * (dimensionless). 1e-5 of the Cornell box is 0.01 mm, far above float rounding there and
 * far below any feature of the scene. */
#define RAY_OFFSET_RELATIVE 1e-5

/* ... but never less than this many float ulps of the largest coordinate, so that a small
 * scene far from the origin still clears its own surfaces after rounding to float. */
#define RAY_OFFSET_ULPS 64.0

/* Russian roulette: paths that have bounced this many times survive each further bounce
 * with probability max channel of the throughput, clamped to [RR_MIN, RR_MAX]. The upper
 * clamp guarantees termination even in a white furnace; the lower keeps rare long paths
 * from carrying huge weights. */
#define RR_START_BOUNCES 5u
#define RR_MIN_SURVIVAL 0.05
#define RR_MAX_SURVIVAL 0.95

/* One light path of a wave. */
typedef struct pt_path {
    rad_rng rng;        /* its own stream, seeded from (seed, pixel, sample) */
    rad_rgb throughput; /* product of Kd / survival probability along the path so far */
    rad_rgb radiance;   /* radiance gathered so far: the path's sample value */
    double bsdf_pdf;    /* solid-angle density of the direction of the current ray, for
                           MIS; 0 for the camera ray (its emission is taken whole) */
    uint32_t bounces;   /* surfaces reflected from so far */
} pt_path;

/* A thread's working memory, allocated once before the parallel loop. */
typedef struct pt_workspace {
    pt_path *paths;       /* WAVE_PATHS; path j is sample j / pixels of tile pixel j % pixels */
    uint32_t *active;     /* path index of each queued ray */
    rad_ray *rays;        /* closest-hit queries, one per live path */
    rad_hit *hits;
    rad_ray *shadow_rays; /* next-event segments of this bounce */
    uint32_t *shadow_path;
    rad_rgb *shadow_value; /* what each segment adds when unoccluded */
    uint8_t *occluded;
    double *mean;         /* TILE * TILE * 3: running mean per pixel and channel */
    double *m2;           /* TILE * TILE * 3: running sum of squared deviations (Welford) */
} pt_workspace;

/* What every path of a call shares; read-only during tracing. */
typedef struct pt_context {
    const rad_scene *scene;
    const rad_tracer *tracer;
    const emitter_set *emitters;
    const rad_vec3 *normals; /* unit front normal of each scene triangle */
    camera_frame frame;
    uint32_t width, height;
    uint32_t spp, max_depth; /* max_depth 0 = no limit */
    uint32_t strata;         /* k: the first k^2 x floor(spp / k^2) samples are stratified */
    uint64_t seed;
    double offset;           /* ray offset in scene units */
    float camera_near;       /* t_near of camera rays */
    const light_set *lights; /* the scene's light sources besides emitters */
    uint32_t shadow_capacity; /* shadow rays per bounce of a wave, at most */
} pt_context;

/* Plain comparisons: fmax is a library call unless NaNs are ruled out, and none occur. */
static double larger(double a, double b) { return a > b ? a : b; }

static double max3(rad_rgb c) { return larger(c.r, larger(c.g, c.b)); }





/* Power heuristic (beta = 2) weight of a strategy with density `a` against one with `b`. */
static double power_heuristic(double a, double b)
{
    double a2 = a * a, b2 = b * b;
    return a2 + b2 > 0 ? a2 / (a2 + b2) : 0;
}

/* A direction from the cosine-weighted hemisphere around the unit normal n (density
 * cos / pi): a uniform point of the unit disk, by rejection from its square (no
 * trigonometry; 4/pi draws of two numbers on average), lifted onto the hemisphere
 * (Malley's method), in the orthonormal basis of Duff et al. 2017. */
static rad_vec3 cosine_direction(rad_vec3 n, rad_rng *rng, double *cos_theta)
{
    double dx, dy, r2;
    do {
        dx = 2.0 * rad_rng_uniform(rng) - 1.0;
        dy = 2.0 * rad_rng_uniform(rng) - 1.0;
        r2 = dx * dx + dy * dy;
    } while (r2 >= 1.0);
    double sign = copysign(1.0, n.z);
    double a = -1.0 / (sign + n.z);
    double b = n.x * n.y * a;
    rad_vec3 t = v3(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
    rad_vec3 s = v3(b, sign + n.y * n.y * a, -n.y);
    double z = sqrt(1.0 - r2);
    *cos_theta = z;
    return v3_add(v3_add(v3_scale(t, dx), v3_scale(s, dy)), v3_scale(n, z));
}

/* Where the camera ray of `sample` of pixel (x, y) goes through the film. The first
 * k^2 * floor(spp / k^2) samples cover the pixel's k x k strata in rounds, jittered; the
 * rest are uniform over the pixel. Each round and each extra sample is an unbiased
 * estimate of the box-filtered pixel on its own, so their mean is too. */
static void film_point(const pt_context *c, rad_rng *rng, uint32_t x, uint32_t y,
                       uint32_t sample, double *px, double *py)
{
    uint32_t k = c->strata, cells = k * k;
    double jx = rad_rng_uniform(rng), jy = rad_rng_uniform(rng);
    if (sample < c->spp / cells * cells) {
        uint32_t cell = sample % cells;
        *px = x + ((cell % k) + jx) / k;
        *py = y + ((cell / k) + jy) / k;
    } else {
        *px = x + jx;
        *py = y + jy;
    }
}

/* The hit point, in double, from the scene triangle and the hit's barycentrics. */
static rad_vec3 hit_point(const rad_scene *scene, const rad_hit *hit)
{
    const uint32_t *v = scene->triangles[hit->triangle].vertex;
    rad_vec3 a = scene->positions[v[0]], b = scene->positions[v[1]], c = scene->positions[v[2]];
    double w0 = 1.0 - (double)hit->u - (double)hit->v, w1 = hit->u, w2 = hit->v;
    return v3(w0 * a.x + w1 * b.x + w2 * c.x, w0 * a.y + w1 * b.y + w2 * c.y,
              w0 * a.z + w1 * b.z + w2 * c.z);
}

/* Queues the next-event segment from point x (normal n, origin o) of path p to a point
 * sampled on the emitters, when it can contribute. Returns 1 when a segment was queued. */
static int queue_light_sample(const pt_context *c, pt_workspace *w, uint32_t slot, uint32_t p,
                              rad_vec3 x, rad_vec3 n, rad_vec3 o, rad_rgb albedo)
{
    pt_path *path = &w->paths[p];
    double u0 = rad_rng_uniform(&path->rng), u1 = rad_rng_uniform(&path->rng),
           u2 = rad_rng_uniform(&path->rng);
    emitter_sample light;
    emitters_sample(c->emitters, c->scene, u0, u1, u2, &light);
    rad_vec3 to_light = v3_sub(light.point, x);
    double distance2 = v3_dot(to_light, to_light);
    if (!(distance2 > 0) || !(light.pdf_area > 0))
        return 0;
    rad_vec3 wi = v3_scale(to_light, 1.0 / sqrt(distance2));
    double cos_surface = v3_dot(n, wi), cos_light = emitter_cosine(&light, wi, NULL);
    if (!(cos_surface > 0) || !(cos_light > 0))
        return 0; /* behind the surface, or a one-sided light's back (it emits from its front) */
    double pdf_light = light.pdf_area * distance2 / cos_light; /* per solid angle */
    double pdf_bsdf = cos_surface / RAD_PI;
    /* Kd/pi Le cos_s cos_l / r^2 / pdf_area = Kd Le (cos_s / pi) / pdf_light */
    double weight = power_heuristic(pdf_light, pdf_bsdf) * pdf_bsdf / pdf_light;
    rad_rgb value = rgb_scale(rgb_mul(rgb_mul(path->throughput, albedo), light.radiance), weight);
    if (!(max3(value) > 0))
        return 0;
    rad_vec3 segment = v3_sub(light.point, o);
    double length = v3_length(segment);
    double t_far = length - c->offset;
    if (!(t_far > 0))
        t_far = 0; /* the light is within the offset: nothing can be in between */
    ray_set(&w->shadow_rays[slot], o, v3_scale(segment, 1.0 / length), 0.0f, (float)t_far);
    w->shadow_path[slot] = p;
    w->shadow_value[slot] = value;
    return 1;
}

/* Extends every live path of the wave by one vertex: the closest hits of the queued rays,
 * emission, next-event segments, and the next rays. Returns the number of rays queued
 * for the next bounce; *rays counts the rays cast. */
static uint32_t extend_paths(const pt_context *c, pt_workspace *w, uint32_t live,
                             uint64_t *rays)
{
    rad_tracer_intersect(c->tracer, w->rays, live, w->hits);
    *rays += live;
    const rad_scene *scene = c->scene;
    uint32_t next = 0, shadows = 0;
    for (uint32_t k = 0; k < live; k++) {
        /* read ray k before slot `next` <= k is overwritten with a new ray */
        const rad_hit hit = w->hits[k];
        uint32_t p = w->active[k];
        pt_path *path = &w->paths[p];
        rad_vec3 d = v3((double)w->rays[k].direction[0], (double)w->rays[k].direction[1],
                        (double)w->rays[k].direction[2]);
        if (hit.triangle == RAD_NO_HIT) {
            /* escaped: the sky's radiance, whole (the sky is never sampled by next-event
             * estimation, so BSDF sampling is its only estimator) */
            if (c->lights->has_sky)
                rgb_add_to(&path->radiance,
                           rgb_mul(path->throughput,
                                   light_set_sky_radiance(c->lights, v3_normalize(d))));
            continue;
        }
        if (!hit.front && !triangle_two_sided(scene, hit.triangle))
            continue; /* met a one-sided surface's back: nothing comes back */
        /* a two-sided surface's back is a front facing the ray, with the same material */
        rad_vec3 n = c->normals[hit.triangle];
        if (!hit.front)
            n = v3_scale(n, -1);

        rad_rgb emitted = material_emission_at(scene, hit.triangle, hit.u, hit.v);
        if (max3(emitted) > 0) {
            double weight = 1.0; /* camera rays see emitters whole */
            double pdf_area = c->emitters->pdf_area_of[hit.triangle];
            if (path->bsdf_pdf > 0 && pdf_area > 0) {
                double distance = (double)hit.t * v3_length(d);
                double cos_light = -v3_dot(n, d) / v3_length(d);
                if (cos_light > 0)
                    weight = power_heuristic(path->bsdf_pdf,
                                             pdf_area * distance * distance / cos_light);
            }
            rgb_add_to(&path->radiance, rgb_scale(rgb_mul(path->throughput, emitted), weight));
        }

        if (c->max_depth && path->bounces >= c->max_depth)
            continue;
        rad_rgb albedo = material_albedo_at(scene, hit.triangle, hit.u, hit.v);
        if (!(max3(albedo) > 0))
            continue;
        rad_vec3 x = hit_point(scene, &hit);
        rad_vec3 o = v3_add(x, v3_scale(n, c->offset));
        if (c->emitters->count)
            shadows += (uint32_t)queue_light_sample(c, w, shadows, p, x, n, o, albedo);
        if (c->lights->sharp_count) {
            /* every point, spot, luminaire and sun light, each by one shadow ray: Kd / pi
             * times its irradiance at x (the sun's disk sampled by the path's numbers) */
            uint32_t count = light_set_rays(c->lights, LIGHTS_SHARP, x, n, c->offset, 0, 1, 0,
                                            &path->rng, &w->shadow_rays[shadows],
                                            &w->shadow_value[shadows]);
            rad_rgb factor = rgb_scale(rgb_mul(path->throughput, albedo), 1.0 / RAD_PI);
            for (uint32_t q = shadows; q < shadows + count; q++) {
                w->shadow_value[q] = rgb_mul(w->shadow_value[q], factor);
                w->shadow_path[q] = p;
            }
            shadows += count;
        }

        double cos_theta;
        rad_vec3 wo = cosine_direction(n, &path->rng, &cos_theta);
        if (!(cos_theta > 0))
            continue; /* a measure-zero grazing draw: the estimate is 0 there */
        path->throughput = rgb_mul(path->throughput, albedo);
        path->bounces++;
        if (path->bounces >= RR_START_BOUNCES) {
            double survive = larger(max3(path->throughput), RR_MIN_SURVIVAL);
            survive = survive < RR_MAX_SURVIVAL ? survive : RR_MAX_SURVIVAL;
            if (rad_rng_uniform(&path->rng) >= survive)
                continue;
            path->throughput = rgb_scale(path->throughput, 1.0 / survive);
        }
        path->bsdf_pdf = cos_theta / RAD_PI;
        ray_set(&w->rays[next], o, wo, 0.0f, INFINITY);
        w->active[next++] = p;
    }
    rad_tracer_occluded(c->tracer, w->shadow_rays, shadows, w->occluded);
    *rays += shadows;
    for (uint32_t s = 0; s < shadows; s++)
        if (!w->occluded[s])
            rgb_add_to(&w->paths[w->shadow_path[s]].radiance, w->shadow_value[s]);
    return next;
}

/* Traces samples [first, first + count) of every pixel of the tile whose top-left pixel is
 * (x0, y0) and size tw x th, and folds them into the tile's running statistics. */
static void trace_wave(const pt_context *c, pt_workspace *w, uint32_t x0, uint32_t y0,
                       uint32_t tw, uint32_t th, uint32_t first, uint32_t count, uint64_t *rays)
{
    uint32_t pixels = tw * th, paths = pixels * count;
    for (uint32_t j = 0; j < paths; j++) {
        uint32_t sample = first + j / pixels, local = j % pixels;
        uint32_t x = x0 + local % tw, y = y0 + local / tw;
        pt_path *path = &w->paths[j];
        path->rng = rad_rng_seed(c->seed, (uint64_t)y * c->width + x, sample);
        path->throughput = (rad_rgb){1, 1, 1};
        path->radiance = (rad_rgb){0, 0, 0};
        path->bsdf_pdf = 0;
        path->bounces = 0;
        double px, py;
        film_point(c, &path->rng, x, y, sample, &px, &py);
        rad_vec3 d = v3_normalize(camera_direction(&c->frame, px, py, c->width, c->height));
        ray_set(&w->rays[j], c->frame.eye, d, c->camera_near, INFINITY);
        w->active[j] = j;
    }
    for (uint32_t live = paths; live > 0;)
        live = extend_paths(c, w, live, rays);

    /* Welford's update, in sample order, so the sums never depend on scheduling */
    for (uint32_t j = 0; j < paths; j++) {
        double n = (double)(first + j / pixels) + 1.0;
        const rad_rgb value = w->paths[j].radiance;
        double v[3] = {value.r, value.g, value.b};
        double *mean = &w->mean[(size_t)(j % pixels) * 3], *m2 = &w->m2[(size_t)(j % pixels) * 3];
        for (int ch = 0; ch < 3; ch++) {
            double delta = v[ch] - mean[ch];
            mean[ch] += delta / n;
            m2[ch] += delta * (v[ch] - mean[ch]);
        }
    }
}

static void trace_tile(const pt_context *c, pt_workspace *w, uint64_t tile, rad_image *image,
                       rad_image *standard_error, uint64_t *rays)
{
    uint32_t tiles_x = (c->width - 1) / TILE + 1; /* width >= 1 */
    uint32_t x0 = (uint32_t)(tile % tiles_x) * TILE, y0 = (uint32_t)(tile / tiles_x) * TILE;
    uint32_t tw = c->width - x0 < TILE ? c->width - x0 : TILE;
    uint32_t th = c->height - y0 < TILE ? c->height - y0 : TILE;
    memset(w->mean, 0, TILE * TILE * 3 * sizeof(*w->mean));
    memset(w->m2, 0, TILE * TILE * 3 * sizeof(*w->m2));
    for (uint32_t first = 0; first < c->spp; first += SAMPLES_PER_WAVE) {
        uint32_t count = c->spp - first < SAMPLES_PER_WAVE ? c->spp - first : SAMPLES_PER_WAVE;
        trace_wave(c, w, x0, y0, tw, th, first, count, rays);
    }
    double n = c->spp;
    for (uint32_t local = 0; local < tw * th; local++) {
        size_t pixel = (size_t)(y0 + local / tw) * c->width + x0 + local % tw;
        for (int ch = 0; ch < 3; ch++) {
            image->rgb[pixel * 3 + ch] = (float)w->mean[local * 3 + ch];
            if (standard_error)
                /* sample standard deviation / sqrt(n); unknown (infinite) from one sample */
                standard_error->rgb[pixel * 3 + ch] =
                    n > 1 ? (float)sqrt(w->m2[local * 3 + ch] / (n * (n - 1))) : INFINITY;
        }
    }
}

/* Camera rays per tile side for its cost estimate. */
#define COST_RAYS 4u

/* cost[k]: tile k's pixels times (0.1 + the fraction of COST_RAYS^2 camera rays through it
 * that hit the scene): rays that leave at once cost almost nothing. The same on every rank
 * (camera rays through fixed film points). Uses w's ray and hit arrays. */
static void estimate_tile_costs(const pt_context *c, uint64_t tiles, pt_workspace *w,
                                double *cost)
{
    uint32_t tiles_x = (c->width - 1) / TILE + 1, per_tile = COST_RAYS * COST_RAYS;
    uint64_t batch = WAVE_PATHS / per_tile; /* tiles per tracer call */
    for (uint64_t first = 0; first < tiles; first += batch) {
        uint64_t count = tiles - first < batch ? tiles - first : batch;
        for (uint64_t k = 0; k < count; k++) {
            uint64_t tile = first + k;
            uint32_t x0 = (uint32_t)(tile % tiles_x) * TILE, y0 = (uint32_t)(tile / tiles_x) * TILE;
            uint32_t tw = c->width - x0 < TILE ? c->width - x0 : TILE;
            uint32_t th = c->height - y0 < TILE ? c->height - y0 : TILE;
            for (uint32_t j = 0; j < per_tile; j++) {
                double px = x0 + tw * ((j % COST_RAYS) + 0.5) / COST_RAYS;
                double py = y0 + th * ((j / COST_RAYS) + 0.5) / COST_RAYS;
                rad_vec3 d = v3_normalize(camera_direction(&c->frame, px, py, c->width, c->height));
                ray_set(&w->rays[k * per_tile + j], c->frame.eye, d, c->camera_near, INFINITY);
            }
        }
        rad_tracer_intersect(c->tracer, w->rays, (uint32_t)(count * per_tile), w->hits);
        for (uint64_t k = 0; k < count; k++) {
            uint64_t tile = first + k;
            uint32_t x0 = (uint32_t)(tile % tiles_x) * TILE, y0 = (uint32_t)(tile / tiles_x) * TILE;
            double pixels = (double)(c->width - x0 < TILE ? c->width - x0 : TILE) *
                            (c->height - y0 < TILE ? c->height - y0 : TILE);
            uint32_t hits = 0;
            for (uint32_t j = 0; j < per_tile; j++)
                hits += w->hits[k * per_tile + j].triangle != RAD_NO_HIT;
            cost[tile] = pixels * (0.1 + (double)hits / per_tile);
        }
    }
}

static void workspace_free(pt_workspace *w)
{
    free(w->paths);
    free(w->active);
    free(w->rays);
    free(w->hits);
    free(w->shadow_rays);
    free(w->shadow_path);
    free(w->shadow_value);
    free(w->occluded);
    free(w->mean);
    free(w->m2);
}

static int workspace_alloc(pt_workspace *w, uint32_t shadow_capacity)
{
    memset(w, 0, sizeof(*w));
    w->paths = rad_alloc_array(WAVE_PATHS, sizeof(*w->paths));
    w->active = rad_alloc_array(WAVE_PATHS, sizeof(*w->active));
    w->rays = rad_alloc_array(WAVE_PATHS, sizeof(*w->rays));
    w->hits = rad_alloc_array(WAVE_PATHS, sizeof(*w->hits));
    w->shadow_rays = rad_alloc_array(shadow_capacity, sizeof(*w->shadow_rays));
    w->shadow_path = rad_alloc_array(shadow_capacity, sizeof(*w->shadow_path));
    w->shadow_value = rad_alloc_array(shadow_capacity, sizeof(*w->shadow_value));
    w->occluded = rad_alloc_array(shadow_capacity, sizeof(*w->occluded));
    w->mean = rad_alloc_array(TILE * TILE * 3, sizeof(*w->mean));
    w->m2 = rad_alloc_array(TILE * TILE * 3, sizeof(*w->m2));
    return w->paths && w->active && w->rays && w->hits && w->shadow_rays && w->shadow_path &&
           w->shadow_value && w->occluded && w->mean && w->m2;
}

rad_status rad_pathtrace(const rad_scene *scene, const rad_camera *camera,
                         const rad_pathtrace_options *options, rad_image *image,
                         rad_image *standard_error, rad_pathtrace_report *report,
                         rad_error *error)
{
    double start = rad_clock_seconds();
    rad_pathtrace_options defaults = {0};
    if (!options)
        options = &defaults;
    if (report)
        memset(report, 0, sizeof(*report));
    if (!scene || !camera || !image)
        return rad_fail(error, RAD_ERR_INVALID, "pathtrace: scene, camera and image are required");
    if (options->threads < 0)
        return rad_fail(error, RAD_ERR_INVALID, "pathtrace: thread count must not be negative");
    if (standard_error &&
        (standard_error->width != image->width || standard_error->height != image->height))
        return rad_fail(error, RAD_ERR_INVALID,
                        "pathtrace: the standard-error image is %ux%u, the image %ux%u",
                        standard_error->width, standard_error->height, image->width,
                        image->height);

    pt_context c;
    memset(&c, 0, sizeof(c));
    rad_status status = camera_frame_make(camera, image->width, image->height, &c.frame, error);
    if (status != RAD_OK)
        return status;
    c.scene = scene;
    c.width = image->width;
    c.height = image->height;
    c.spp = options->samples_per_pixel ? options->samples_per_pixel : RAD_DEFAULT_PATHTRACE_SPP;
    c.max_depth = options->max_depth;
    c.seed = options->seed;
    c.strata = (uint32_t)floor(sqrt((double)c.spp));
    while ((uint64_t)c.strata * c.strata > c.spp) /* guard the rounding of sqrt */
        c.strata--;
    while ((uint64_t)(c.strata + 1) * (c.strata + 1) <= c.spp)
        c.strata++;

    rad_vec3 lo, hi;
    rad_scene_bounds(scene, &lo, &hi);
    double diagonal = v3_length(v3_sub(hi, lo));
    if (!(diagonal > 0))
        diagonal = 1;
    double largest = fmax(fmax(fmax(fabs(lo.x), fabs(hi.x)), fmax(fabs(lo.y), fabs(hi.y))),
                          fmax(fabs(lo.z), fabs(hi.z)));
    c.offset = fmax(RAY_OFFSET_RELATIVE * diagonal, RAY_OFFSET_ULPS * FLT_EPSILON * largest);
    c.camera_near = (float)(RAD_CAMERA_NEAR * diagonal);

    int threads = options->threads > 0 ? options->threads : omp_get_max_threads();
    emitter_set emitters;
    memset(&emitters, 0, sizeof(emitters));
    rad_tracer *tracer = NULL;
    rad_vec3 *normals = NULL;
    pt_workspace *workspaces = NULL;
    uint32_t *owner = NULL;

    status = emitters_build(scene, &emitters, error);
    if (status == RAD_OK)
        status = rad_tracer_create_for_scene(RAD_TRACER_EMBREE, scene, &tracer, error);
    if (status == RAD_OK) {
        normals = rad_alloc_array(scene->triangle_count, sizeof(*normals));
        workspaces = rad_alloc_array((size_t)threads, sizeof(*workspaces));
        if (!normals || !workspaces)
            status = rad_fail(error, RAD_ERR_NOMEM, "pathtrace: out of memory");
    }
    light_set lights;
    if (status == RAD_OK) {
        light_set_init(&lights, scene);
        c.lights = &lights;
        /* per path and bounce: one emitter sample and one ray per sharp light */
        c.shadow_capacity = WAVE_PATHS * (1 + lights.sharp_count);
        for (int t = 0; t < threads && status == RAD_OK; t++)
            if (!workspace_alloc(&workspaces[t], c.shadow_capacity))
                status = rad_fail(error, RAD_ERR_NOMEM, "pathtrace: out of memory");
    }
    status = ranks_agree(status, "pathtrace", error); /* every rank, before working together */
    if (status != RAD_OK)
        goto done;
    for (uint32_t t = 0; t < scene->triangle_count; t++) {
        const uint32_t *v = scene->triangles[t].vertex;
        rad_vec3 a = scene->positions[v[0]];
        normals[t] = v3_normalize(v3_cross(v3_sub(scene->positions[v[1]], a),
                                           v3_sub(scene->positions[v[2]], a)));
    }
    c.tracer = tracer;
    c.emitters = &emitters;
    c.normals = normals;

    uint64_t tiles_x = (c.width - 1) / TILE + 1, tiles_y = (c.height - 1) / TILE + 1;
    uint64_t tiles = tiles_x * tiles_y;
    /* over several ranks: who traces which tile (owner NULL: this process, all), decided
     * by rank 0 alone so that no rank can disagree */
    int rank = ranks_rank();
    if (ranks_count() > 1) {
        double *cost = rank == 0 ? rad_alloc_array(tiles, sizeof(double)) : NULL;
        owner = rad_alloc_array(tiles, sizeof(uint32_t));
        bool failed = (rank == 0 && !cost) || !owner || tiles > UINT32_MAX;
        if (!failed && rank == 0) {
            estimate_tile_costs(&c, tiles, &workspaces[0], cost);
            failed = partition_by_cost(cost, (uint32_t)tiles, ranks_count(), owner, error) !=
                     RAD_OK;
        }
        free(cost);
        if (ranks_failures(failed))
            goto nomem;
        ranks_broadcast(owner, tiles * sizeof(uint32_t));
    }
    uint64_t rank_tiles = 0;
    for (uint64_t tile = 0; tile < tiles; tile++)
        rank_tiles += !owner || owner[tile] == (uint32_t)rank;
    render_progress progress = render_progress_start(options->progress, options->progress_user,
                                                     "pathtrace", rank_tiles);
    uint64_t rays = 0;
    double tiles_start = rad_clock_seconds();
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads) reduction(+ : rays)
    for (uint64_t tile = 0; tile < tiles; tile++) {
        if (owner && owner[tile] != (uint32_t)rank)
            continue;
        trace_tile(&c, &workspaces[omp_get_thread_num()], tile, image, standard_error, &rays);
        render_progress_step(&progress);
    }
    double rank_seconds = rad_clock_seconds() - tiles_start;
    if (owner) {
        rad_image *images[2] = {image, standard_error};
        status = ranks_gather_tiles(images, standard_error ? 2 : 1, TILE, owner, error);
        ranks_sum(&rays, 1);
        if (status != RAD_OK)
            goto done;
    }
    render_progress_finish(&progress);
    if (report) {
        report->rays = rays;
        report->seconds = rad_clock_seconds() - start;
        report->rank_tiles = rank_tiles;
        report->rank_seconds = rank_seconds;
    }
    goto done;
nomem:
    status = rad_fail(error, RAD_ERR_NOMEM, "pathtrace: out of memory");
done:
    if (workspaces)
        for (int t = 0; t < threads; t++)
            workspace_free(&workspaces[t]);
    free(workspaces);
    free(owner);
    free(normals);
    rad_tracer_destroy(tracer);
    emitters_free(&emitters);
    return status;
}
