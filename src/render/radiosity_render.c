/*
 * radiosity_render.c - images of a radiosity solution, and the two-pass method.
 *
 * The patches are split into triangles (display_mesh.h: quads along their first diagonal,
 * patches with T-vertices on their edges through those) and handed to a tracer; each
 * pixel averages k x k jittered stratified primary rays (box filter). A hit on a front
 * face takes the radiance interpolated from the vertex values with the hit's barycentrics;
 * a back face or a miss is black. A two-sided surface's patches have twins (rad_patch.twin:
 * the same cell facing the other way, with its own radiosity): only the front patches go to
 * the tracer, and a hit on a front patch's back is shaded as its twin at that point (the
 * twin's display triangle holding the point, the barycentrics there). Pixels whose first
 * samples disagree (silhouettes, the light's rim) get edge_samples more, and pixels on an
 * emitter's rim RIM_SIDE^2 more again (with the emitters' light at the vertices or the
 * pixels, whose 256 edge samples leave the rim the noisiest part). With the scene's
 * materials given, a hit on a surface with Ks > 0 also sends a mirror ray, weighted by Ks,
 * whose hit is shaded the same way (the radiosity solution replaces Whitted's ambient
 * term), up to a depth.
 * Random numbers come from (seed, pixel). With the scene's textures (albedo or emission),
 * a textured patch's vertices hold the irradiance (B_i - E_i) / (pi rho_i) instead, E_i and
 * rho_i the patch inputs the solve used (passed in, or built once here), and a hit shows
 * L_e(point) + albedo(point) x that, both read from the textures at the hit
 * (scene/patch_materials.h), so texture detail finer than the patches survives and an
 * emission texture shows its own texels.
 */
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/error.h"
#include "core/random.h"
#include "core/rgb.h"
#include "core/tolerance.h"
#include "core/vec3.h"
#include "lights/direct_light.h"
#include "render/camera.h"
#include "render/emitter_light.h"
#include "render/emitter_shadows.h"
#include "render/gather.h"
#include "render/light_refine.h"
#include "lights/emitters.h"
#include "parallel/ranks.h"
#include "render/progress.h"
#include "render/vertex_radiance.h"
#include "reconstruct/display_locate.h"
#include "reconstruct/display_mesh.h"
#include "scene/patch_materials.h"
#include "trace/ray.h"

#define MAX_STRATA 16u
#define EDGE_CONTRAST 0.1        /* relative luminance spread that makes an edge */
#define EDGE_STREAM 0x5EED0EDCEull /* keeps edge samples' random numbers apart */
#define LIGHT_STREAM 0x5EED11647ull /* the same for shadow rays toward light sources */
#define LIGHT_BATCH 4096u          /* shadow rays traced together, at most (Embree takes
                                      them in chunks of 256: more only costs memory) */
#define MAX_DIRECT_SAMPLES 1024u   /* emitter samples per pixel sample, at most */
/* The default render's emitter samples per pixel sample in a penumbra (a display triangle
 * whose corners' shadow rays disagree or find a part of the light): there the emitters'
 * light is computed at the pixel, elsewhere interpolated from the vertices, whose linear
 * interpolation cut off a penumbra's kinks (the floor in the short block's shadow at the
 * Cornell box's front edge 12 % too bright on an 8 x 8 block at 256 x 256). Such a pixel's
 * edge test is by the surfaces its samples meet, as with --direct pixel. Measured with a
 * saved solution, 256 x 256, 2 threads, against the 16384-spp reference (render seconds;
 * block / pixel relative RMSE; the same per image between two seeds): interpolated
 * everywhere 1.25 s, 0.782 / 1.055 %, 0.370 / 0.410 %; 32 samples 1.64 s, 0.658 / 1.033 %,
 * 0.370 / 0.442 %; 64 2.03 s, 0.657 / 1.025 %, 0.368 / 0.423 %; 128 2.62 s, 0.656 / 1.023 %,
 * 0.368 / 0.416 % (64 with LIGHT_BATCH 4096 instead of 65536: 1.89 s, the same image).
 * test_contact_shadow's profile, the largest difference from the exact one: 2.29 % of the
 * open floor with 32 (past its 2 %), 1.94 % with 64. */
/* Where the emitters' light behind the occluders is exact (emitter_shadows.h) a
 * penumbra's hit takes that instead, with no shadow ray: these samples serve scenes past
 * its limits. */
#define PENUMBRA_DIRECT_SAMPLES 64u
/* A hit takes the emitters' light exactly (emitter_shadows.h) when at most this many
 * triangles stand between it and each emitting polygon; once more do at one of a pixel's
 * hits, its later hits sample (the rule is the row's own, in its fixed order: the same for
 * any thread count). The exact light's cost grows with its occluders: on the Cornell box
 * (1.9 a query) it is a tenth of the 64 shadow rays' time, on a furnished room of 9,942
 * triangles (10.7 a query, 3 % past 64) twice it: its render (saved solution, 256 x 256)
 * 6.7-6.8 s with shadow rays, 8.1-8.3 s exact everywhere, 6.7-7.0 s with this limit; the
 * Cornell box's images the same as exact everywhere within their noise. */
#define PIXEL_EXACT_OCCLUDERS 8u
/* In a penumbra an edge or rim sample (the extra samples of a pixel, 256 or 1280 of
 * them) takes this share of a first sample's emitter samples: 64 each had made a
 * penumbra's edge pixel cost 16384 shadow rays. Cornell box 128 x 128, block / pixel
 * relative RMSE against the 65536-spp reference, the same (0.398 / 0.702 % -> 0.399 /
 * 0.703 %; seed 2 0.403 / 0.707 -> 0.403 / 0.706); the render at 256 x 256 0.2 s shorter. */
#define EXTRA_SHADOW_SHARE 16u
/* How the default render takes the emitters' light at the hits on a display triangle:
 * interpolated from its corners (none of them sees the light, or all see all of it and
 * its exact value is not at hand), computed at the hit with shadow rays (a penumbra), or,
 * where every corner sees all of the light and its unshadowed value is exact
 * (emitter_unshadowed_exact) with at most OPEN_LIGHT_MAX_TRIANGLES emitting triangles,
 * that value at the hit: linear interpolation of the open light, concave where it peaks,
 * fell short there (the Cornell box's back wall 0.6-0.9 % dark). Each hit then costs a
 * contour integral per emitting triangle: a lamp of 64 triangles doubled a render's time,
 * so more keep the interpolation. */
enum { DISPLAY_INTERPOLATED, DISPLAY_PENUMBRA, DISPLAY_OPEN_LIGHT };
#define OPEN_LIGHT_MAX_TRIANGLES 8u
#define EMITTER_STREAM 0x5EEDE3177ull /* the per-pixel shifts of the emitters' samples */
/* A pixel on an emitter's rim (its corners and first samples meet an emitting surface and
 * another) gets RIM_PASSES x RIM_SIDE^2 / RIM_PASSES more samples besides its edge samples,
 * RIM_SIDE x RIM_SIDE strata taken a band of rows per pass: the light is a hundred times
 * brighter than what is around it, so the share of the pixel it covers decides the pixel,
 * and 272 samples left the Cornell box's rim pixels at RMS 6.0 % against the reference at
 * 128 x 128 (8 x 8 blocks holding the rim 2-3 % off, from seed to seed); 1.8 % with these
 * (test_render_accuracy). There are few such pixels. */
#define RIM_SIDE 32u
#define RIM_PASSES 4u
#define RIM_STREAM 0x5EED0121Bull /* the rim samples' jitter, and their light's streams */

/* One thread's rays of one image row, compacted bounce by bounce. */
typedef struct row_work {
    rad_ray *rays;
    rad_hit *hits;
    rad_rgb *weight;  /* product of the Ks met so far */
    uint32_t *sample; /* the sample (pixel x, stratum) a ray belongs to */
    rad_rgb *sum;     /* radiance gathered per sample: first samples, then edge samples
                         (or, after those are summed, a pass of rim samples) */
    uint8_t *edge;    /* per pixel of the row: gets edge samples */
    double *level;    /* per pixel of the row: mean luminance of its first samples */
    uint32_t row;     /* the image row being rendered (random numbers) */
    uint32_t *edge_pixel; /* the pixels of the row that get edge samples, in order */
    uint8_t *rim;         /* per pixel of the row: on an emitter's rim (RIM_SIDE) */
    rad_rgb *rim_sum;     /* per pixel of the row: a rim pixel's samples summed */
    uint32_t rim_pass;    /* 0: first and edge samples; p: the p-th pass of rim samples */
    uint32_t *first_surface; /* per first sample: the surface its camera ray met
                                (UINT32_MAX: none); with the direct light per pixel,
                                edges are where these differ, not where noise does; at
                                the vertices, also where some emit and some do not */
    uint32_t *corner_surface; /* the same at the row's pixel corners: 2 (W + 1) */
    uint8_t *sampled_pixel;   /* per pixel of the row: the emitters' light at its hits is
                                 sampled, not exact (more than PIXEL_EXACT_OCCLUDERS met) */
    uint8_t *first_penumbral; /* per first sample: whether it met a penumbra (NULL: none
                                 is told apart) */
    /* shadow rays toward the sharp light sources from the hits of a bounce */
    rad_ray *light_rays;
    rad_rgb *light_value;   /* radiance the ray adds to its sample when unblocked */
    uint32_t *light_sample;
    uint8_t *light_blocked;
    uint32_t light_count, light_capacity;
    /* cosine-weighted rays toward the emitters (their MIS half), closest-hit queries */
    rad_ray *cosine_rays;
    rad_hit *cosine_hits;
    double *cosine_of;
    rad_rgb *cosine_factor;
    uint32_t *cosine_sample;
    uint32_t cosine_count, cosine_capacity;
} row_work;

typedef struct shading {
    const rad_mesh *mesh;
    const uint32_t (*triangles)[3]; /* render triangles, into mesh vertices */
    const uint32_t *patch_of;       /* render triangle -> patch */
    const uint32_t *first_triangle; /* per patch (and one past the last): its first render
                                       triangle; NULL when no patch has a twin */
    const rad_rgb *radiance;        /* per mesh vertex */
    const rad_vec3 *positions;      /* per display vertex */
    const rad_material *materials;  /* NULL: no mirror rays */
    float t_near;
    double leave;                   /* how far mirror rays start off a surface (scene units) */
    const patch_material_lookup *textures; /* NULL: no textured surface */
    const rad_patch_inputs *inputs; /* per patch: the means the solve used (with textures
                                       or light sources) */
    const light_set *lights;        /* NULL: no light sources besides emitters */
    const rad_tracer *tracer;       /* for shadow rays */
    uint32_t strata;                /* first samples per pixel, k^2 */
    uint64_t seed;
    bool irradiance;                /* pixels hold the irradiance arriving at the surface */
    const emitter_set *emitters;    /* NULL: the emitters' direct light comes from the
                                       solution, interpolated, not per pixel */
    const rad_scene *scene;
    bool emitters_exact;            /* their unshadowed light summed exactly (ratio
                                       estimator: emitter_light.h), no cosine rays */
    uint32_t emitter_samples;       /* per pixel sample */
    size_t per_row;                 /* first samples of a row: W k^2 */
    uint32_t edge_strata;           /* edge samples of an edge pixel */
    const rad_tracer *scene_tracer; /* the scene's own triangles: the emitters hit */
    const uint8_t *emitter_way;     /* NULL: `emitters` light every hit; else per display
                                       triangle, how its hits take the emitters' light
                                       (DISPLAY_*: from the vertices, shadow rays at the
                                       hit, or the exact open light at the hit) */
    const rad_rgb *without_emitters; /* per display vertex: the radiance without the
                                        emitters' light, shown where a hit adds its own */
    const rad_rgb (*open_nodes)[6];  /* NULL, or per display triangle whose hits take the
                                        emitters' light (DISPLAY_OPEN_LIGHT, and with
                                        emitters_exact DISPLAY_PENUMBRA): their unshadowed
                                        irradiance at its corners and its edges' midpoints
                                        (open_light_nodes) */
    const emitter_shadows *shadows;  /* NULL, or with emitters_exact: their light behind
                                        every occluder, exactly (no shadow rays) */
} shading;

/* The open light on a display triangle as the quadratic through its six nodes (corners
 * 0, 1, 2, then the midpoints of edges 01, 12, 20) at barycentrics (1 - u - v, u, v). */
static rad_rgb open_light_at(const rad_rgb node[6], double u, double v)
{
    const double b0 = 1 - u - v, b1 = u, b2 = v;
    const double weight[6] = {b0 * (2 * b0 - 1), b1 * (2 * b1 - 1), b2 * (2 * b2 - 1),
                              4 * b0 * b1,       4 * b1 * b2,       4 * b2 * b0};
    rad_rgb sum = {0, 0, 0};
    for (int k = 0; k < 6; k++)
        rgb_add_to(&sum, rgb_scale(node[k], weight[k]));
    return rgb_max0(sum);
}

/* For every display triangle whose hits take the emitters' light (not interpolated): the
 * emitters' unshadowed irradiance, exact, at its six nodes, for open_light_at. The
 * unshadowed light is smooth over a patch (the patch's plane clips the emitters alike at
 * every point of it), and the quadratic through the nodes stands for the exact value a
 * hit took before (Cornell box 256 x 256: the image within 1.6e-5 on blocks, 7.4e-5 a
 * pixel, relative RMS), at a hundredth of the cost: per hit it had been a contour
 * integral over every emitting triangle, a tenth of the pixels' time. */
static void open_light_nodes(const emitter_set *emitters, const rad_scene *scene,
                             const rad_mesh *mesh, const display_mesh *display,
                             const rad_vec3 *positions, const uint8_t *emitter_way,
                             int threads, rad_rgb (*nodes)[6])
{
#pragma omp parallel for schedule(dynamic, 256) num_threads(threads)
    for (int64_t t = 0; t < (int64_t)display->triangle_count; t++) {
        if (emitter_way[t] == DISPLAY_INTERPOLATED)
            continue;
        const uint32_t *v = display->triangles[t];
        const rad_vec3 n = mesh->patches[display->patch_of[t]].normal;
        rad_vec3 at[6] = {positions[v[0]], positions[v[1]], positions[v[2]]};
        for (int k = 0; k < 3; k++)
            at[3 + k] = v3_scale(v3_add(at[k], at[(k + 1) % 3]), 0.5);
        for (int k = 0; k < 6; k++)
            nodes[t][k] = emitter_unshadowed_irradiance(emitters, scene, at[k], n);
    }
}

/* Whether a first sample of pixel x met a penumbra, whose light it computed itself (with
 * a little noise: its luminance tells no edge). */
static bool penumbra_met(const row_work *w, uint32_t x, unsigned strata)
{
    if (!w->first_penumbral)
        return false;
    for (unsigned s = 0; s < strata; s++)
        if (w->first_penumbral[(size_t)x * strata + s])
            return true;
    return false;
}

static double mean_luminance(const rad_rgb *samples, unsigned count)
{
    double mean = 0;
    for (unsigned s = 0; s < count; s++)
        mean += rgb_luminance(samples[s]);
    return mean / count;
}

/* Two neighbouring pixels' luminances differ by more than EDGE_CONTRAST of the larger. */
static bool is_step(double a, double b) { return fabs(a - b) > EDGE_CONTRAST * fmax(a, b); }

/* A pixel is an edge when the luminance of its first samples spreads by more than
 * EDGE_CONTRAST of their mean. */
static bool is_edge(const rad_rgb *samples, unsigned count, double mean)
{
    double lo = INFINITY, hi = 0;
    for (unsigned s = 0; s < count; s++) {
        double y = rgb_luminance(samples[s]);
        lo = fmin(lo, y);
        hi = fmax(hi, y);
    }
    return hi - lo > EDGE_CONTRAST * mean;
}

/* Whether the surfaces a pixel's corners (four, in the row's corner table) and first
 * samples met disagree on emitting (surface_emits[s]; UINT32_MAX: none met): the pixel
 * holds an emitter's rim. Its samples' luminance may not show it: a sliver of the light
 * that none of them met. */
static bool emitter_rim(const uint32_t *seen, unsigned count, const uint32_t *corner,
                        uint32_t x, uint32_t W, const uint8_t *surface_emits)
{
#define EMITS(s) ((s) != UINT32_MAX && surface_emits[s])
    bool first = EMITS(seen[0]);
    if (EMITS(corner[x]) != first || EMITS(corner[x + 1]) != first ||
        EMITS(corner[W + 1 + x]) != first || EMITS(corner[W + 2 + x]) != first)
        return true;
    for (unsigned q = 1; q < count; q++)
        if (EMITS(seen[q]) != first)
            return true;
    return false;
#undef EMITS
}

/* A textured patch's radiance at a hit: the emitted radiance at the point plus the albedo
 * at the point times the interpolated irradiance (/ pi). Where the probe finds no scene
 * triangle, the patch's means stand in: E_i / pi and rho_i. */
static rad_rgb textured_radiance(const shading *sh, const rad_ray *ray, const rad_hit *hit,
                                 uint32_t patch_index, rad_rgb irradiance, rad_rgb *albedo_at)
{
    const rad_patch *patch = &sh->mesh->patches[patch_index];
    rad_vec3 point = v3(ray->origin[0] + (double)hit->t * ray->direction[0],
                        ray->origin[1] + (double)hit->t * ray->direction[1],
                        ray->origin[2] + (double)hit->t * ray->direction[2]);
    rad_rgb albedo = sh->inputs->albedo[patch_index];
    rad_rgb emission = rgb_scale(sh->inputs->exitance[patch_index], 1.0 / RAD_PI);
    patch_material_at(sh->textures, point, patch->normal, 2 * patch->bulge, &albedo, &emission);
    *albedo_at = albedo;
    return rgb_add(emission, rgb_mul(albedo, irradiance));
}

/* The twin's render triangle under `point` (a point of its front patch's plane) and the
 * barycentrics there: of the twin's triangles, the one where the point is deepest inside
 * (the largest least barycentric), so a point on their shared edge takes either. */
static uint32_t twin_triangle(const shading *sh, uint32_t twin, rad_vec3 point, double *u,
                              double *v)
{
    uint32_t best = RAD_NO_HIT;
    double best_depth = -INFINITY;
    for (uint32_t t = sh->first_triangle[twin]; t < sh->first_triangle[twin + 1]; t++) {
        const uint32_t *corner = sh->triangles[t];
        rad_vec3 a = sh->positions[corner[0]];
        rad_vec3 e1 = v3_sub(sh->positions[corner[1]], a);
        rad_vec3 e2 = v3_sub(sh->positions[corner[2]], a);
        rad_vec3 d = v3_sub(point, a);
        double d11 = v3_dot(e1, e1), d12 = v3_dot(e1, e2), d22 = v3_dot(e2, e2);
        double d1 = v3_dot(d, e1), d2 = v3_dot(d, e2);
        double det = d11 * d22 - d12 * d12;
        if (!(det > 0))
            continue;
        double bu = (d22 * d1 - d12 * d2) / det, bv = (d11 * d2 - d12 * d1) / det;
        double depth = fmin(1 - bu - bv, fmin(bu, bv));
        if (depth > best_depth) {
            best_depth = depth;
            best = t;
            *u = bu;
            *v = bv;
        }
    }
    return best;
}

/* Traces the pending shadow rays and adds the light of those that got through; and the
 * cosine-weighted rays, adding what the emitters they hit send. */
static void flush_lights(const shading *sh, row_work *w)
{
    if (w->cosine_count) {
        rad_tracer_intersect(sh->scene_tracer, w->cosine_rays, w->cosine_count, w->cosine_hits);
        for (uint32_t k = 0; k < w->cosine_count; k++) {
            rad_rgb value = emitter_cosine_value(sh->emitters, sh->scene, &w->cosine_rays[k],
                                                 &w->cosine_hits[k], w->cosine_of[k],
                                                 sh->emitter_samples);
            rgb_add_to(&w->sum[w->cosine_sample[k]], rgb_mul(value, w->cosine_factor[k]));
        }
        w->cosine_count = 0;
    }
    if (w->light_count == 0)
        return;
    rad_tracer_occluded(sh->tracer, w->light_rays, w->light_count, w->light_blocked);
    for (uint32_t k = 0; k < w->light_count; k++)
        if (!w->light_blocked[k])
            rgb_add_to(&w->sum[w->light_sample[k]], w->light_value[k]);
    w->light_count = 0;
}

/* Queues the shadow rays of the sharp light sources (point, spot, luminaire, sun) and of
 * the emitters from a hit: each adds weight x albedo / pi x its irradiance to the sample
 * when unblocked. The emitters' samples of one pixel are stratified together: sample
 * `slot` is the pixel's index-th, and takes the index-th share of the triangle choice and
 * the Halton points after the previous samples', with the pixel's own shift. */
static void queue_lights(const shading *sh, row_work *w, uint32_t slot, rad_vec3 point,
                         const rad_patch *patch, rad_rgb factor, bool emitters,
                         const rad_rgb *unshadowed)
{
    uint32_t room = (sh->lights ? sh->lights->sharp_count : 0) +
                    (emitters ? sh->emitter_samples : 0);
    if (w->light_count + room > w->light_capacity ||
        (emitters && !sh->emitters_exact &&
         w->cosine_count + sh->emitter_samples > w->cosine_capacity))
        flush_lights(sh, w);
    rad_rng rng = rad_rng_seed(sh->seed ^ LIGHT_STREAM ^ (w->rim_pass * RIM_STREAM), w->row, slot);
    double leave = 2 * patch->behind + sh->leave;
    uint32_t count = 0, index;
    uint32_t pixel;
    if (slot < sh->per_row) {
        pixel = slot / sh->strata;
        index = slot % sh->strata;
    } else {
        pixel = w->edge_pixel[(slot - sh->per_row) / sh->edge_strata];
        index = sh->strata + w->rim_pass * sh->edge_strata +
                (uint32_t)((slot - sh->per_row) % sh->edge_strata);
    }
    if (sh->lights && sh->lights->sharp_count)
        count = light_set_rays(sh->lights, LIGHTS_SHARP, point, patch->normal, leave,
                               index % sh->strata, sh->strata, 0, &rng,
                               &w->light_rays[w->light_count], &w->light_value[w->light_count]);
    if (emitters) {
        rad_rng per_pixel = rad_rng_seed(sh->seed ^ EMITTER_STREAM, w->row, pixel);
        double turn = rad_rng_uniform(&per_pixel), shift1 = rad_rng_uniform(&per_pixel),
               shift2 = rad_rng_uniform(&per_pixel);
        rad_ray *rays = &w->light_rays[w->light_count + count];
        rad_rgb *values = &w->light_value[w->light_count + count];
        if (sh->emitters_exact) {
            /* the unshadowed light exactly, shared out over the samples: those that get
             * through bring their share (none to trace where it is 0: a ceiling around a
             * lamp that hangs below it) */
            rad_rgb open = unshadowed ? *unshadowed
                                      : emitter_unshadowed_irradiance(sh->emitters, sh->scene,
                                                                      point, patch->normal);
            /* the light behind every occluder, exactly, where few stand in the way:
             * nothing to trace (a pixel where more do samples from then on) */
            rad_rgb shadowed;
            bool exact = !rgb_is_zero(open) && sh->shadows && !w->sampled_pixel[pixel];
            if (exact) {
                exact = emitter_shadows_irradiance(
                    sh->shadows, v3_add(point, v3_scale(patch->normal, leave)), patch->normal,
                    PIXEL_EXACT_OCCLUDERS, &shadowed);
                w->sampled_pixel[pixel] = !exact;
            }
            if (exact) {
                rgb_add_to(&w->sum[slot], rgb_mul(shadowed, factor));
            } else if (!rgb_is_zero(open)) {
                /* in the default render's penumbrae an edge or rim sample, one of
                 * hundreds in its pixel, takes a sixteenth: its pixel's first samples have
                 * the full number, and together they follow on from those along the same
                 * Halton points (with --direct pixel every hit has only a few) */
                const bool extra = slot >= sh->per_row && sh->emitter_way;
                uint32_t samples = extra ? (sh->emitter_samples + EXTRA_SHADOW_SHARE - 1) /
                                               EXTRA_SHADOW_SHARE
                                         : sh->emitter_samples;
                uint32_t first = extra ? sh->strata * sh->emitter_samples +
                                             (index - sh->strata) * samples
                                       : index * sh->emitter_samples;
                uint32_t made = emitter_light_rays_alone(
                    sh->emitters, sh->scene, point, patch->normal, leave, samples, turn, first,
                    shift1, shift2, rays, values);
                if (made == 0 && extra) /* all of its few behind the horizon: the full set */
                    made = emitter_light_rays_alone(sh->emitters, sh->scene, point,
                                                    patch->normal, leave, sh->emitter_samples,
                                                    turn, index * sh->emitter_samples, shift1,
                                                    shift2, rays, values);
                emitter_scale_to(open, values, made);
                count += made;
            }
        } else
            count += emitter_light_rays_mis(sh->emitters, sh->scene, point, patch->normal, leave,
                                            sh->emitter_samples, turn,
                                            index * sh->emitter_samples, shift1, shift2, rays,
                                            values);
    }
    if (emitters && !sh->emitters_exact) {
        uint32_t c = w->cosine_count;
        emitter_cosine_rays(point, patch->normal, leave, sh->emitter_samples, &rng,
                            &w->cosine_rays[c], &w->cosine_of[c]);
        for (uint32_t k = c; k < c + sh->emitter_samples; k++) {
            w->cosine_factor[k] = factor;
            w->cosine_sample[k] = slot;
        }
        w->cosine_count += sh->emitter_samples;
    }
    for (uint32_t k = 0; k < count; k++) {
        uint32_t q = w->light_count + k;
        w->light_value[q] = rgb_mul(w->light_value[q], factor);
        w->light_sample[q] = slot;
    }
    w->light_count += count;
}

/* Adds each hit's interpolated radiance (times the ray's weight) to its sample and, when
 * mirrors are allowed, writes the mirror rays of specular hits to the front of the arrays.
 * Returns how many rays are left for the next bounce. */
static uint32_t shade_hits(const shading *sh, row_work *w, uint32_t count, bool mirrors)
{
    uint32_t next = 0;
    for (uint32_t r = 0; r < count; r++) {
        const rad_hit *hit = &w->hits[r];
        if (hit->triangle == RAD_NO_HIT) {
            /* the sky (or environment) behind open geometry */
            if (sh->lights && sh->lights->has_sky && !sh->irradiance) {
                const rad_ray *ray = &w->rays[r];
                rad_vec3 d = v3_normalize(v3(ray->direction[0], ray->direction[1], ray->direction[2]));
                rgb_add_to(&w->sum[w->sample[r]],
                           rgb_mul(w->weight[r], light_set_sky_radiance(sh->lights, d)));
            }
            continue;
        }
        uint32_t triangle = hit->triangle;
        double hit_u = hit->u, hit_v = hit->v;
        uint32_t patch_index = sh->patch_of[triangle];
        if (!hit->front) {
            /* the back of a one-sided patch is black; of a two-sided one, its twin */
            uint32_t twin = sh->mesh->patches[patch_index].twin;
            if (twin == 0 || !sh->first_triangle)
                continue;
            const rad_ray *ray = &w->rays[r];
            rad_vec3 point = v3(ray->origin[0] + (double)hit->t * ray->direction[0],
                                ray->origin[1] + (double)hit->t * ray->direction[1],
                                ray->origin[2] + (double)hit->t * ray->direction[2]);
            triangle = twin_triangle(sh, twin - 1, point, &hit_u, &hit_v);
            if (triangle == RAD_NO_HIT)
                continue;
            patch_index = twin - 1;
        }
        const uint32_t *v = sh->triangles[triangle];
        /* the emitters' light here: at every hit, or at a penumbra's (shadow rays), or,
         * in the open light, its exact unshadowed value */
        const uint8_t region = sh->emitter_way ? sh->emitter_way[triangle] : DISPLAY_PENUMBRA;
        const bool emitter_light = sh->emitters && region == DISPLAY_PENUMBRA;
        const bool open_light = sh->emitters && region == DISPLAY_OPEN_LIGHT;
        const rad_rgb *L =
            (emitter_light || open_light) && sh->emitter_way ? sh->without_emitters : sh->radiance;
        rad_rgb weight = w->weight[r];
        rad_rgb interpolated = rgb_add(rgb_scale(L[v[0]], 1.0 - hit_u - hit_v),
                                       rgb_add(rgb_scale(L[v[1]], hit_u), rgb_scale(L[v[2]], hit_v)));
        rad_rgb albedo = sh->inputs ? sh->inputs->albedo[patch_index] : (rad_rgb){0, 0, 0};
        if (sh->irradiance) {
            /* the vertices hold irradiance / pi; the sharp sources come below, whole */
            interpolated = rgb_scale(interpolated, RAD_PI);
            albedo = (rad_rgb){RAD_PI, RAD_PI, RAD_PI};
        } else if (patch_material_textured(sh->textures, sh->mesh->patches[patch_index].material))
            interpolated =
                textured_radiance(sh, &w->rays[r], hit, patch_index, interpolated, &albedo);
        rgb_add_to(&w->sum[w->sample[r]], rgb_mul(weight, interpolated));
        const bool sharp = sh->lights && sh->lights->sharp_count > 0;
        if ((open_light || sharp || emitter_light) && !rgb_is_zero(albedo)) {
            /* the light this hit takes itself: the open light's exact value, or shadow
             * rays toward the sharp sources and the emitters */
            const rad_ray *ray = &w->rays[r];
            rad_vec3 point = v3(ray->origin[0] + (double)hit->t * ray->direction[0],
                                ray->origin[1] + (double)hit->t * ray->direction[1],
                                ray->origin[2] + (double)hit->t * ray->direction[2]);
            const rad_patch *hit_patch = &sh->mesh->patches[patch_index];
            rad_rgb factor = rgb_scale(rgb_mul(weight, albedo), 1.0 / RAD_PI);
            if (open_light)
                rgb_add_to(&w->sum[w->sample[r]],
                           rgb_mul(factor,
                                   sh->open_nodes
                                       ? open_light_at(sh->open_nodes[triangle], hit_u, hit_v)
                                       : emitter_unshadowed_irradiance(sh->emitters, sh->scene,
                                                                       point,
                                                                       hit_patch->normal)));
            if (sharp || emitter_light) {
                rad_rgb unshadowed;
                const bool nodes = emitter_light && sh->open_nodes && sh->emitters_exact;
                if (nodes)
                    unshadowed = open_light_at(sh->open_nodes[triangle], hit_u, hit_v);
                queue_lights(sh, w, w->sample[r], point, hit_patch, factor, emitter_light,
                             nodes ? &unshadowed : NULL);
            }
        }
        if (!mirrors || !sh->materials || sh->irradiance)
            continue;
        const rad_patch *patch = &sh->mesh->patches[patch_index];
        rad_rgb ks = sh->materials[patch->material].specular;
        if (!(ks.r > 0 || ks.g > 0 || ks.b > 0))
            continue;
        const rad_ray *ray = &w->rays[r];
        rad_vec3 d = v3(ray->direction[0], ray->direction[1], ray->direction[2]);
        rad_vec3 p = v3(ray->origin[0] + hit->t * d.x, ray->origin[1] + hit->t * d.y,
                        ray->origin[2] + hit->t * d.z);
        rad_vec3 n = patch->normal;
        rad_vec3 mirror = v3_normalize(v3_sub(d, v3_scale(n, 2 * v3_dot(d, n))));
        /* leave the surface on its front side: nudged along the normal, past the float
         * rounding of the hit point */
        rad_vec3 origin = v3_add(p, v3_scale(n, sh->leave));
        w->weight[next] = rgb_mul(weight, ks);
        w->sample[next] = w->sample[r];
        ray_set(&w->rays[next], origin, mirror, sh->t_near, INFINITY);
        next++;
    }
    return next;
}

static void trace_samples(const shading *sh, const rad_tracer *tracer, row_work *w,
                          uint32_t count, unsigned max_depth, bool first)
{
    for (unsigned depth = 0; count > 0; depth++) {
        rad_tracer_intersect_coherent(tracer, w->rays, count, w->hits);
        if (first && depth == 0 && w->first_surface)
            for (uint32_t r = 0; r < count; r++)
                w->first_surface[w->sample[r]] =
                    w->hits[r].triangle == RAD_NO_HIT
                        ? UINT32_MAX
                        : sh->mesh->patches[sh->patch_of[w->hits[r].triangle]].surface;
        if (first && depth == 0 && w->first_penumbral)
            for (uint32_t r = 0; r < count; r++)
                w->first_penumbral[w->sample[r]] =
                    w->hits[r].triangle != RAD_NO_HIT &&
                    sh->emitter_way[w->hits[r].triangle] == DISPLAY_PENUMBRA;
        count = shade_hits(sh, w, count, depth < max_depth);
        flush_lights(sh, w);
    }
}

/* With textures or light sources: the texture lookup (NULL without textures), the patch
 * inputs (the caller's, else built here into *built) and the per-patch values to
 * reconstruct, without the direct light of the sharp sources (point, spot, luminaire, sun:
 * H_sharp), which is added at each hit instead: on textured patches the irradiance
 * (B - E) / rho - H_sharp (0 where rho is 0), elsewhere the exitance B - rho H_sharp. All
 * NULL when there is no scene or neither textures nor light sources. */
static rad_status inputs_begin(const rad_render_options *options, const rad_mesh *mesh,
                               const rad_rgb *B, bool need,
                               patch_material_lookup **lookup,
                               const rad_patch_inputs **inputs, rad_patch_inputs **built,
                               rad_rgb **shaded, rad_error *error)
{
    *lookup = NULL;
    *inputs = NULL;
    *built = NULL;
    *shaded = NULL;
    const rad_scene *scene = options->scene;
    if (options->inputs && options->inputs->n != mesh->patch_count)
        return rad_fail(error, RAD_ERR_INVALID,
                        "render: the patch inputs are for %u patches, the mesh has %u",
                        options->inputs->n, mesh->patch_count);
    if (options->irradiance && !scene)
        return rad_fail(error, RAD_ERR_INVALID,
                        "render: an irradiance image needs the scene (options.scene)");
    if (!scene || (scene->texture_count == 0 && scene->light_count == 0 && !options->irradiance &&
                   !need))
        return RAD_OK;
    rad_status status = RAD_OK;
    if (scene->texture_count > 0)
        status = patch_material_lookup_create(scene, lookup, error);
    if (status != RAD_OK ||
        (!*lookup && scene->light_count == 0 && !options->irradiance && !need))
        return status;
    if (!options->inputs) {
        status = rad_patch_inputs_build(scene, mesh, built, error);
        if (status != RAD_OK)
            return status;
    }
    *inputs = options->inputs ? options->inputs : *built;
    *shaded = rad_alloc_array(mesh->patch_count, sizeof(**shaded));
    if (!*shaded)
        return rad_fail(error, RAD_ERR_NOMEM, "out of memory for textures");
    for (uint32_t p = 0; p < mesh->patch_count; p++) {
        const double *b = &B[p].r, *e = &(*inputs)->exitance[p].r;
        const double *rho = &(*inputs)->albedo[p].r;
        /* what the hits add themselves: the sharp sources' */
        const double *h = &(*inputs)->direct_sharp[p].r;
        double *out = &(*shaded)[p].r;
        if (options->irradiance) {
            /* (B - E) / rho is the irradiance; a black patch shows its direct light only */
            const double *all = &(*inputs)->direct[p].r, *sources = &(*inputs)->direct_sharp[p].r;
            /* (the light sources' H holds no emitter light: only their sharp part goes) */
            for (int c = 0; c < 3; c++)
                out[c] = fmax(rho[c] > 0 ? (b[c] - e[c]) / rho[c] - h[c] : all[c] - sources[c], 0);
            continue;
        }
        if (!patch_material_textured(*lookup, mesh->patches[p].material)) {
            for (int c = 0; c < 3; c++)
                out[c] = fmax(b[c] - rho[c] * h[c], 0);
            continue;
        }
        for (int c = 0; c < 3; c++)
            out[c] = rho[c] > 0 ? fmax((b[c] - e[c]) / rho[c] - h[c], 0) : 0;
    }
    return RAD_OK;
}

/* Camera ray `ray` of a row through the image point (px, py), for sample `slot` (its sum
 * starts at 0): first samples, edge samples and rim samples alike. */
static void start_sample(row_work *w, const camera_frame *frame, uint32_t ray, size_t slot,
                         double px, double py, uint32_t W, uint32_t H, float t_near)
{
    rad_vec3 d = v3_normalize(camera_direction(frame, px, py, W, H));
    ray_set(&w->rays[ray], frame->eye, d, t_near, INFINITY);
    w->weight[ray] = (rad_rgb){1, 1, 1};
    w->sample[ray] = (uint32_t)slot;
    w->sum[slot] = (rad_rgb){0, 0, 0};
}

/* Pixel (x, y) holds the mean of `count` samples summing to `sum`. */
static void write_pixel(rad_image *image, uint32_t x, uint32_t y, rad_rgb sum, double count)
{
    float *pixel = &image->rgb[((size_t)y * image->width + x) * 3];
    pixel[0] = (float)(sum.r / count);
    pixel[1] = (float)(sum.g / count);
    pixel[2] = (float)(sum.b / count);
}

/* Whether a mirror ray may leave some patch (a material with Ks > 0): then any surface
 * may show in the image. */
static bool any_mirror(const rad_mesh *mesh, const rad_material *materials)
{
    if (!materials)
        return false;
    for (uint32_t p = 0; p < mesh->patch_count; p++) {
        rad_rgb ks = materials[mesh->patches[p].material].specular;
        if (ks.r > 0 || ks.g > 0 || ks.b > 0)
            return true;
    }
    return false;
}

/* shown[v] = 1 for every corner of a patch p with seen[p], 0 for every other vertex. */
static void mark_corners(const rad_mesh *mesh, const uint8_t *seen, uint8_t *shown)
{
    for (uint32_t v = 0; v < mesh->vertex_count; v++)
        shown[v] = 0;
    for (uint32_t p = 0; p < mesh->patch_count; p++)
        for (uint32_t k = 0; seen[p] && k < mesh->patches[p].vertex_count; k++)
            shown[mesh->patches[p].vertex[k]] = 1;
}

/* shown[v] for the mesh's vertices: whether a pixel may show the light at vertex v. A ray
 * through every pixel's centre marks the patch it meets first (and a two-sided patch's
 * twin, when it meets the back), and so are the patches that share a corner with a marked
 * one (small pieces seen between pixel centres); every corner of a marked patch is shown,
 * and so are the parents whose gathered light a shown vertex takes (they have lower
 * indices). A patch seen only between pixel centres and away from those keeps its corners
 * unshown: they gather with fewer rays, not none. False when out of memory. */
static bool shown_vertices(const rad_mesh *mesh, const display_mesh *display,
                           const rad_tracer *tracer, const camera_frame *frame, uint32_t W,
                           uint32_t H, float t_near, const vertex_parents *parents, int threads,
                           uint8_t *shown)
{
    uint8_t *seen = rad_alloc_array(mesh->patch_count ? mesh->patch_count : 1, 1);
    rad_ray *rays = rad_alloc_array((size_t)threads * W, sizeof(*rays));
    rad_hit *hits = rad_alloc_array((size_t)threads * W, sizeof(*hits));
    bool made = seen && rays && hits;
    if (made) {
#pragma omp parallel for schedule(dynamic, 4) num_threads(threads)
        for (int64_t y = 0; y < (int64_t)H; y++) {
            const int thread = omp_get_thread_num();
            rad_ray *row_rays = &rays[(size_t)thread * W];
            rad_hit *row_hits = &hits[(size_t)thread * W];
            for (uint32_t x = 0; x < W; x++)
                ray_set(&row_rays[x], frame->eye,
                        v3_normalize(camera_direction(frame, x + 0.5, (double)y + 0.5, W, H)),
                        t_near, INFINITY);
            rad_tracer_intersect_coherent(tracer, row_rays, W, row_hits);
            for (uint32_t x = 0; x < W; x++) {
                if (row_hits[x].triangle == RAD_NO_HIT)
                    continue;
                const uint32_t p = display->patch_of[row_hits[x].triangle];
                const uint32_t twin = mesh->patches[p].twin;
#pragma omp atomic write
                seen[p] = 1;
                if (!row_hits[x].front && twin) {
#pragma omp atomic write
                    seen[twin - 1] = 1;
                }
            }
        }
        mark_corners(mesh, seen, shown);
        for (uint32_t p = 0; p < mesh->patch_count; p++) /* and the patches around those */
            for (uint32_t k = 0; k < mesh->patches[p].vertex_count; k++)
                seen[p] |= shown[mesh->patches[p].vertex[k]];
        mark_corners(mesh, seen, shown);
        for (uint32_t v = mesh->vertex_count; parents && v-- > 0;)
            for (uint32_t k = 0; shown[v] && k < parents[v].count; k++)
                shown[parents[v].vertex[k]] = 1;
    }
    free(seen);
    free(rays);
    free(hits);
    return made;
}

static rad_status render_mesh(const rad_mesh *mesh, const rad_rgb *B,
                              const vertex_parents *parents, const rad_camera *camera,
                              const rad_render_options *options, rad_image *image,
                              rad_error *error)
{
    uint32_t W = image->width, H = image->height;
    camera_frame frame;
    rad_status status = camera_frame_make(camera, W, H, &frame, error);
    if (status != RAD_OK)
        return status;
    unsigned spp =
        options->samples_per_pixel ? options->samples_per_pixel : RAD_DEFAULT_RENDER_SPP;
    unsigned k = (unsigned)lround(sqrt((double)spp));
    k = k < 1 ? 1 : k > MAX_STRATA ? MAX_STRATA : k;
    if (options->threads < 0)
        return rad_fail(error, RAD_ERR_INVALID, "render: thread count %d is negative",
                        options->threads);
    int threads = options->threads > 0 ? options->threads : omp_get_max_threads();

    /* the display triangles (patches split through their T-vertices) and the radiance at
     * each vertex */
    display_mesh display = {0};
    rad_rgb *radiance = NULL;
    rad_vec3 *positions = NULL;
    rad_tracer *tracer = NULL;
    row_work *work = NULL;
    patch_material_lookup *lookup = NULL;
    const rad_patch_inputs *inputs = NULL;
    rad_patch_inputs *built_inputs = NULL;
    rad_rgb *shaded = NULL;
    uint32_t *first_triangle = NULL;
    uint8_t *surface_emits = NULL; /* at the vertices: per surface, whether it emits */
    light_set lights;
    const light_set *lights_ptr = NULL;
    emitter_set emitters = {0};
    const emitter_set *emitters_ptr = NULL;
    rad_tracer *scene_tracer = NULL;
    display_locator *locator = NULL;
    uint8_t *hidden = NULL;
    rad_rgb *reflected = NULL;
    rad_rgb (*open_nodes)[6] = NULL; /* the default render: the open light's nodes */
    uint8_t *shown = NULL; /* per mesh vertex: a pixel may show it (NULL: every one) */
    uint8_t *sees = NULL, *emitter_way = NULL; /* the default render: how each display
                                                  triangle takes the emitters' light */
    rad_rgb *without_emitters = NULL;
    const emitter_set *pixel_emitters = NULL; /* those whose light some pixels compute */
    emitter_shadows *shadows = NULL; /* their light exactly, where it can be */
    bool agreed = false; /* every rank has passed ranks_agree (collective over MPI ranks) */
    status = display_mesh_build(mesh, true, &display, error);
    if (status != RAD_OK)
        goto done;
    radiance = rad_alloc_array(display.vertex_count, sizeof(*radiance));
    positions = rad_alloc_array(display.vertex_count, sizeof(*positions));
    if (!radiance || !positions)
        goto nomem;
    display_mesh_positions(mesh, &display, positions);
    rad_vec3 lo, hi;
    v3_bounds(mesh->vertices, mesh->vertex_count, &lo, &hi);
    double diagonal = mesh->vertex_count ? v3_length(v3_sub(hi, lo)) : 1;
    /* hit points are float: their error grows with the distance from the origin */
    double leave = vertex_radiance_leave(mesh);
    uint32_t emitter_samples =
        options->direct_samples ? options->direct_samples : RAD_DEFAULT_DIRECT_SAMPLES;
    if (emitter_samples > MAX_DIRECT_SAMPLES)
        emitter_samples = MAX_DIRECT_SAMPLES;

    /* at the vertices: the emitters' light (unless each pixel takes it), the sky's (the
     * gather rays that leave the scene) and the light reflected (the sharp sources' is the
     * hits' own either way) */
    rad_direct_light direct_light = options->direct_light;
    if (direct_light == RAD_DIRECT_PIXEL && !(options->scene && rad_scene_has_emitter(options->scene)))
        direct_light = RAD_DIRECT_VERTEX; /* no emitter light to take per pixel */
    if (direct_light == RAD_DIRECT_VERTEX && !vertex_radiance_applies(options->scene))
        direct_light = RAD_DIRECT_SOLUTION;
    if (direct_light == RAD_DIRECT_PIXEL || direct_light == RAD_DIRECT_VERTEX) {
        status = emitters_build(options->scene, &emitters, error);
        if (status == RAD_OK) /* their light exactly, where it can be */
            status = emitter_shadows_build(options->scene, &emitters, &shadows, error);
        if (status == RAD_OK)
            status = rad_tracer_create_for_scene(RAD_TRACER_EMBREE, options->scene,
                                                 &scene_tracer, error);
        if (status != RAD_OK)
            goto done;
        if (direct_light == RAD_DIRECT_PIXEL)
            emitters_ptr = &emitters;
    }
    pixel_emitters = emitters_ptr;
    status = inputs_begin(options, mesh, B, direct_light != RAD_DIRECT_SOLUTION,
                          &lookup, &inputs, &built_inputs,
                          &shaded, error);
    if (status != RAD_OK)
        goto done;
    if (options->scene && options->scene->light_count > 0) {
        light_set_init(&lights, options->scene);
        lights_ptr = &lights;
    }

    /* the tracer sees the front patches: the twins come after them (rad_mesh), and so do
     * their display triangles, which are in patch order */
    uint32_t traced = display_mesh_front_triangles(mesh, &display);
    if (traced < display.triangle_count) {
        first_triangle = rad_alloc_array((size_t)mesh->patch_count + 1, sizeof(*first_triangle));
        if (!first_triangle)
            goto nomem;
        for (uint32_t p = 0, t = 0; p <= mesh->patch_count; p++) {
            while (t < display.triangle_count && display.patch_of[t] < p)
                t++;
            first_triangle[p] = t;
        }
    }
    status = rad_tracer_create(RAD_TRACER_EMBREE, positions, display.vertex_count,
                               (const uint32_t(*)[3])display.triangles, traced, &tracer, error);
    if (status != RAD_OK)
        goto done;
    /* the radiance at the vertices, patches no one sees left out */
    hidden = rad_alloc_array(mesh->patch_count ? mesh->patch_count : 1, sizeof(*hidden));
    if (!hidden)
        goto nomem;
    gather_view view = {mesh,   (const uint32_t(*)[3])display.triangles,
                        display.patch_of, NULL,
                        B,      inputs ? inputs->exitance : NULL,
                        lights_ptr, tracer, NULL, NULL};
    display_hidden_patches(mesh, tracer, leave, hidden, NULL, 0);
    if (direct_light != RAD_DIRECT_SOLUTION) {
        /* what gather rays meet: the reflected light (B - E) / pi at the vertices */
        reflected = rad_alloc_array(display.vertex_count, sizeof(*reflected));
        if (!reflected ||
            !vertex_radiance_reflected(mesh, &display, B, inputs->exitance, hidden, reflected))
            goto nomem;
        view.reflected = reflected;
        /* the gather's rays against the scene's triangles, placed in the display mesh */
        status = display_locator_build(options->scene, scene_tracer, mesh, &display, positions,
                                       traced,
                                       (uint64_t)VERTEX_LIGHT_BYTES_PER_PATCH * mesh->patch_count,
                                       threads, &locator, error);
        if (status != RAD_OK)
            goto done;
        view.scene_tracer = scene_tracer;
        view.locator = locator;
        if (direct_light == RAD_DIRECT_VERTEX && emitters.count > 0) {
            /* the emitters' light at the penumbrae's pixels, the rest from the vertices */
            sees = rad_alloc_array(mesh->vertex_count ? mesh->vertex_count : 1, 1);
            emitter_way = rad_alloc_array(display.triangle_count ? display.triangle_count : 1, 1);
            without_emitters = rad_alloc_array(display.vertex_count, sizeof(*without_emitters));
            if (!sees || !emitter_way || !without_emitters)
                goto nomem;
            pixel_emitters = &emitters;
            emitter_samples = PENUMBRA_DIRECT_SAMPLES;
        }
        if (!any_mirror(mesh, options->materials)) {
            shown = rad_alloc_array(mesh->vertex_count ? mesh->vertex_count : 1, 1);
            if (!shown || !shown_vertices(mesh, &display, tracer, &frame, W, H,
                                          (float)(RAD_CAMERA_NEAR * diagonal), parents, threads,
                                          shown))
                goto nomem;
        }
        vertex_radiance_job job = {
            .mesh = mesh,
            .display = &display,
            .scene = options->scene,
            .inputs = inputs,
            .lookup = lookup,
            .irradiance = options->irradiance,
            .emitters = &emitters,
            .shadows = shadows,
            .scene_tracer = scene_tracer,
            .view = &view,
            .sharp = lights_ptr && lights.sharp_count > 0 ? lights_ptr : NULL,
            .sharp_at_hits = true, /* each hit adds them */
            .hidden = hidden,
            .parents = parents,
            .sees = sees,
            .without_emitters = without_emitters,
            .penumbra_at_pixels = sees != NULL,
            .shown = shown,
            .leave = leave,
            .emitters_at_hits = direct_light == RAD_DIRECT_PIXEL,
            .seed = options->seed,
            .threads = threads,
            .over_ranks = ranks_count() > 1, /* rad_render is collective */
        };
        if (job.over_ranks) { /* a rank that failed before is at `done`, agreeing there */
            status = ranks_agree(RAD_OK, "render", error);
            agreed = status != RAD_OK; /* then all stop, agreed */
            if (status != RAD_OK)
                goto done;
        }
        status = vertex_radiance(&job, radiance, NULL, error);
        if (status != RAD_OK)
            goto done;
        const bool open_exact = emitter_unshadowed_exact(&emitters, options->scene) &&
                                emitters.count <= OPEN_LIGHT_MAX_TRIANGLES;
        for (uint32_t t = 0; emitter_way && t < display.triangle_count; t++) {
            /* corners that disagree, or one that sees a part (a point the display mesh
             * added on an edge: unknown, so a part) */
            uint8_t least = VERTEX_SEES_ALL, most = VERTEX_SEES_NONE;
            for (int c = 0; c < 3; c++) {
                uint32_t v = display.triangles[t][c];
                uint8_t seen = v < mesh->vertex_count ? sees[v] : VERTEX_SEES_PART;
                least = seen < least ? seen : least;
                most = seen > most ? seen : most;
            }
            emitter_way[t] = least != most || least == VERTEX_SEES_PART ? DISPLAY_PENUMBRA
                           : least == VERTEX_SEES_ALL && open_exact        ? DISPLAY_OPEN_LIGHT
                                                                           : DISPLAY_INTERPOLATED;
        }
        if (emitter_way && open_exact) {
            open_nodes = rad_alloc_array(display.triangle_count ? display.triangle_count : 1,
                                         sizeof(*open_nodes));
            if (!open_nodes)
                goto nomem;
            open_light_nodes(&emitters, options->scene, mesh, &display, positions, emitter_way,
                             threads, open_nodes);
        }
    } else if (!display_mesh_radiance_weighted(mesh, &display, shaded ? shaded : B, hidden,
                                               radiance))
        goto nomem;

    float t_near = (float)(RAD_CAMERA_NEAR * diagonal);

    size_t per_row = (size_t)W * k * k;
    /* with the direct light per pixel or at the vertices the image is accurate enough for
     * the light's rim to show: its pixels get four times the samples */
    uint32_t edge_samples = options->edge_samples            ? options->edge_samples
                            : direct_light != RAD_DIRECT_SOLUTION ? 4 * RAD_DEFAULT_EDGE_SAMPLES
                                                                  : RAD_DEFAULT_EDGE_SAMPLES;
    unsigned edge_k = (unsigned)lround(sqrt((double)edge_samples));
    edge_k = edge_k < 1 ? 1 : edge_k > MAX_STRATA ? MAX_STRATA : edge_k;
    size_t per_row_edges = (size_t)W * edge_k * edge_k;
    size_t ray_capacity = per_row > per_row_edges ? per_row : per_row_edges;
    if (ray_capacity < 2 * ((size_t)W + 1))
        ray_capacity = 2 * ((size_t)W + 1); /* the corner rays */
    unsigned max_depth = options->max_depth ? options->max_depth : RAD_DEFAULT_MAX_DEPTH;
    if (direct_light != RAD_DIRECT_SOLUTION && inputs && rad_scene_has_emitter(options->scene)) {
        /* the light's rim, found by the surfaces met (emitter_rim) */
        uint32_t surfaces = 0;
        for (uint32_t p = 0; p < mesh->patch_count; p++)
            surfaces = mesh->patches[p].surface + 1 > surfaces ? mesh->patches[p].surface + 1
                                                              : surfaces;
        surface_emits = rad_alloc_array(surfaces ? surfaces : 1, 1);
        if (!surface_emits)
            goto nomem;
        for (uint32_t p = 0; p < mesh->patch_count; p++) {
            const rad_rgb e = inputs->exitance[p];
            if (e.r > 0 || e.g > 0 || e.b > 0)
                surface_emits[mesh->patches[p].surface] = 1;
        }
    }
    const bool emitters_exact =
        pixel_emitters && emitter_unshadowed_exact(pixel_emitters, options->scene);
    work = rad_alloc_array((size_t)threads, sizeof(*work));
    if (!work)
        goto nomem;
    for (int th = 0; th < threads; th++) {
        row_work *w = &work[th];
        w->rays = rad_alloc_array(ray_capacity, sizeof(*w->rays));
        w->hits = rad_alloc_array(ray_capacity, sizeof(*w->hits));
        w->weight = rad_alloc_array(ray_capacity, sizeof(*w->weight));
        w->sample = rad_alloc_array(ray_capacity, sizeof(*w->sample));
        w->sum = rad_alloc_array(per_row + per_row_edges, sizeof(*w->sum));
        w->edge = rad_alloc_array(W, sizeof(*w->edge));
        w->level = rad_alloc_array(W, sizeof(*w->level));
        if (!w->rays || !w->hits || !w->weight || !w->sample || !w->sum || !w->edge || !w->level)
            goto nomem;
        w->sampled_pixel = rad_alloc_array(W, 1);
        if (!w->sampled_pixel)
            goto nomem;
        w->edge_pixel = rad_alloc_array(W, sizeof(*w->edge_pixel));
        w->rim = rad_alloc_array(W, sizeof(*w->rim));
        w->rim_sum = rad_alloc_array(W, sizeof(*w->rim_sum));
        if (!w->edge_pixel || !w->rim || !w->rim_sum)
            goto nomem;
        if (emitters_ptr || surface_emits) {
            w->first_surface = rad_alloc_array(per_row, sizeof(*w->first_surface));
            w->corner_surface = rad_alloc_array(2 * ((size_t)W + 1), sizeof(*w->corner_surface));
            if (!w->first_surface || !w->corner_surface)
                goto nomem;
        }
        if (emitter_way && w->first_surface) {
            w->first_penumbral = rad_alloc_array(per_row, 1);
            if (!w->first_penumbral)
                goto nomem;
        }
        uint32_t room = (lights_ptr ? lights.sharp_count : 0) + (pixel_emitters ? emitter_samples : 0);
        if (room > 0) {
            w->light_capacity = LIGHT_BATCH > room ? LIGHT_BATCH : room;
            w->light_rays = rad_alloc_array(w->light_capacity, sizeof(*w->light_rays));
            w->light_value = rad_alloc_array(w->light_capacity, sizeof(*w->light_value));
            w->light_sample = rad_alloc_array(w->light_capacity, sizeof(*w->light_sample));
            w->light_blocked = rad_alloc_array(w->light_capacity, sizeof(*w->light_blocked));
            if (!w->light_rays || !w->light_value || !w->light_sample || !w->light_blocked)
                goto nomem;
        }
        if (pixel_emitters && !emitters_exact) { /* their MIS half (queue_lights) */
            w->cosine_capacity = LIGHT_BATCH;
            w->cosine_rays = rad_alloc_array(LIGHT_BATCH, sizeof(*w->cosine_rays));
            w->cosine_hits = rad_alloc_array(LIGHT_BATCH, sizeof(*w->cosine_hits));
            w->cosine_of = rad_alloc_array(LIGHT_BATCH, sizeof(*w->cosine_of));
            w->cosine_factor = rad_alloc_array(LIGHT_BATCH, sizeof(*w->cosine_factor));
            w->cosine_sample = rad_alloc_array(LIGHT_BATCH, sizeof(*w->cosine_sample));
            if (!w->cosine_rays || !w->cosine_hits || !w->cosine_of || !w->cosine_factor ||
                !w->cosine_sample)
                goto nomem;
        }
    }
    shading shade = {mesh,      (const uint32_t(*)[3])display.triangles,
                     display.patch_of, first_triangle,
                     radiance,  positions,
                     options->materials,
                     t_near,    leave,
                     lookup,    inputs,
                     lights_ptr, tracer,
                     k * k,     options->seed,
                     options->irradiance,
                     pixel_emitters, options->scene,
                     emitters_exact,
                     emitter_samples, per_row,
                     edge_k * edge_k, scene_tracer,
                     emitter_way, without_emitters,
                     (const rad_rgb(*)[6])open_nodes, emitters_exact ? shadows : NULL};

    /* over several MPI ranks the rows are dealt out in turn (every pixel's random numbers
     * are its own, so each row comes out as in a serial run), then summed: every pixel is
     * non-zero on its row's rank alone, so the sum is that rank's value, exactly */
    status = ranks_agree(RAD_OK, "render", error);
    agreed = true;
    if (status != RAD_OK)
        goto done;
    const uint32_t rank = (uint32_t)ranks_rank(), ranks = (uint32_t)ranks_count();
    render_progress progress = render_progress_start(options->progress, options->progress_user,
                                                     "render", (H - rank + ranks - 1) / ranks);
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (uint32_t y = 0; y < H; y++) {
        if (y % ranks != rank) {
            memset(&image->rgb[(size_t)y * W * 3], 0, (size_t)W * 3 * sizeof(float));
            continue;
        }
        int thread = omp_get_thread_num();
        row_work *w = &work[thread];
        w->row = y;
        memset(w->sampled_pixel, 0, W);
        if (w->first_surface) {
            /* the surfaces at the pixels' corners: an edge that crosses a pixel but none of
             * its first samples (the light's rim covering a tenth of it) still shows */
            for (uint32_t c = 0; c < 2 * (W + 1); c++) {
                rad_vec3 d = v3_normalize(camera_direction(&frame, c % (W + 1), y + c / (W + 1), W, H));
                ray_set(&w->rays[c], frame.eye, d, t_near, INFINITY);
            }
            rad_tracer_intersect_coherent(tracer, w->rays, 2 * (W + 1), w->hits);
            for (uint32_t c = 0; c < 2 * (W + 1); c++)
                w->corner_surface[c] = w->hits[c].triangle == RAD_NO_HIT
                                           ? UINT32_MAX
                                           : mesh->patches[display.patch_of[w->hits[c].triangle]].surface;
        }
        for (uint32_t x = 0; x < W; x++) {
            rad_rng rng = rad_rng_seed(options->seed, y, x);
            for (unsigned s = 0; s < k * k; s++) {
                double px = x + ((s % k) + rad_rng_uniform(&rng)) / k;
                double py = y + ((s / k) + rad_rng_uniform(&rng)) / k;
                size_t index = (size_t)x * k * k + s;
                start_sample(w, &frame, (uint32_t)index, index, px, py, W, H, t_near);
            }
        }
        trace_samples(&shade, tracer, w, (uint32_t)per_row, max_depth, true);

        /* edges: pixels whose first samples disagree (a silhouette, the light's rim) get
         * edge_k x edge_k more, so that high-contrast edges are antialiased */
        uint32_t extra = 0;
        for (uint32_t x = 0; x < W; x++)
            w->level[x] = mean_luminance(&w->sum[(size_t)x * k * k], k * k);
        for (uint32_t x = 0; x < W; x++) {
            const bool on_rim = surface_emits &&
                                emitter_rim(&w->first_surface[(size_t)x * k * k], k * k,
                                            w->corner_surface, x, W, surface_emits);
            w->rim[x] = on_rim && edge_k * edge_k == RIM_SIDE * RIM_SIDE / RIM_PASSES;
            /* an edge shows inside the pixel's samples, or as a step to a row neighbour
             * (samples that all fell on one side of an edge crossing the pixel) */
            if (on_rim) {
                w->edge[x] = true;
            } else if (emitters_ptr || penumbra_met(w, x, k * k)) {
                /* the direct light per pixel is noisy: an edge is where the camera rays
                 * meet different surfaces (a silhouette, a crease, the light's rim) */
                const uint32_t *seen = &w->first_surface[(size_t)x * k * k];
                const uint32_t *corner = w->corner_surface;
                bool differ = corner[x] != seen[0] || corner[x + 1] != seen[0] ||
                              corner[W + 1 + x] != seen[0] || corner[W + 2 + x] != seen[0];
                for (unsigned q = 1; q < k * k && !differ; q++)
                    differ = seen[q] != seen[0];
                w->edge[x] = differ;
            } else
                w->edge[x] = is_edge(&w->sum[(size_t)x * k * k], k * k, w->level[x]) ||
                             (x > 0 && !penumbra_met(w, x - 1, k * k) &&
                              is_step(w->level[x], w->level[x - 1])) ||
                             (x + 1 < W && !penumbra_met(w, x + 1, k * k) &&
                              is_step(w->level[x], w->level[x + 1]));
            if (!w->edge[x])
                continue;
            w->edge_pixel[extra / (edge_k * edge_k)] = x;
            rad_rng rng = rad_rng_seed(options->seed ^ EDGE_STREAM, y, x);
            for (unsigned s = 0; s < edge_k * edge_k; s++) {
                double px = x + ((s % edge_k) + rad_rng_uniform(&rng)) / edge_k;
                double py = y + ((s / edge_k) + rad_rng_uniform(&rng)) / edge_k;
                start_sample(w, &frame, extra, per_row + extra, px, py, W, H, t_near);
                extra++;
            }
        }
        if (extra)
            trace_samples(&shade, tracer, w, extra, max_depth, false);

        uint32_t next_extra = 0;
        for (uint32_t x = 0; x < W; x++) {
            rad_rgb sum = {0, 0, 0};
            unsigned count = k * k;
            for (unsigned s = 0; s < k * k; s++)
                rgb_add_to(&sum, w->sum[(size_t)x * k * k + s]);
            if (w->edge[x]) {
                for (unsigned s = 0; s < edge_k * edge_k; s++)
                    rgb_add_to(&sum, w->sum[per_row + next_extra++]);
                count += edge_k * edge_k;
            }
            if (w->rim[x]) /* written after its rim samples, below */
                w->rim_sum[x] = sum;
            else
                write_pixel(image, x, y, sum, count);
        }
        bool rims = false;
        for (uint32_t x = 0; x < W && !rims; x++)
            rims = w->rim[x];
        /* the rim pixels' own samples, a band of RIM_SIDE / RIM_PASSES rows of the
         * RIM_SIDE x RIM_SIDE strata per pass (edge_k^2 samples a pixel, in the edge
         * samples' place: those are summed) */
        const unsigned band = RIM_SIDE / RIM_PASSES, per_pass = RIM_SIDE * band;
        for (unsigned pass = 0; rims && pass < RIM_PASSES; pass++) {
            uint32_t n = 0, rim_pixels = 0;
            for (uint32_t x = 0; x < W; x++) {
                if (!w->rim[x])
                    continue;
                w->edge_pixel[rim_pixels++] = x;
                rad_rng rng = rad_rng_seed(options->seed ^ RIM_STREAM ^ pass, y, x);
                for (unsigned s = 0; s < per_pass; s++, n++) {
                    double px = x + ((s % RIM_SIDE) + rad_rng_uniform(&rng)) / RIM_SIDE;
                    double py = y + (pass * band + s / RIM_SIDE + rad_rng_uniform(&rng)) / RIM_SIDE;
                    start_sample(w, &frame, n, per_row + n, px, py, W, H, t_near);
                }
            }
            w->rim_pass = pass + 1;
            trace_samples(&shade, tracer, w, n, max_depth, false);
            w->rim_pass = 0;
            for (uint32_t i = 0; i < rim_pixels; i++)
                for (unsigned s = 0; s < per_pass; s++)
                    rgb_add_to(&w->rim_sum[w->edge_pixel[i]], w->sum[per_row + i * per_pass + s]);
        }
        for (uint32_t x = 0; rims && x < W; x++) {
            if (!w->rim[x])
                continue;
            write_pixel(image, x, y, w->rim_sum[x], k * k + edge_k * edge_k + RIM_SIDE * RIM_SIDE);
        }
        render_progress_step(&progress);
    }
    render_progress_finish(&progress);
    if (ranks > 1)
        ranks_sum_floats(image->rgb, (uint64_t)W * H * 3);
    goto done;
nomem:
    status = rad_fail(error, RAD_ERR_NOMEM, "out of memory for rendering");
done:
    if (!agreed) /* failed before the ranks agreed: the others learn it there */
        status = ranks_agree(status, "render", error);
    if (work)
        for (int th = 0; th < threads; th++) {
            free(work[th].rays);
            free(work[th].hits);
            free(work[th].weight);
            free(work[th].sample);
            free(work[th].sum);
            free(work[th].edge);
            free(work[th].level);
            free(work[th].edge_pixel);
            free(work[th].rim);
            free(work[th].rim_sum);
            free(work[th].first_surface);
            free(work[th].first_penumbral);
            free(work[th].sampled_pixel);
            free(work[th].corner_surface);
            free(work[th].cosine_rays);
            free(work[th].cosine_hits);
            free(work[th].cosine_of);
            free(work[th].cosine_factor);
            free(work[th].cosine_sample);
            free(work[th].light_rays);
            free(work[th].light_value);
            free(work[th].light_sample);
            free(work[th].light_blocked);
        }
    free(work);
    free(surface_emits);
    rad_tracer_destroy(tracer);
    rad_tracer_destroy(scene_tracer);
    display_locator_destroy(locator);
    emitter_shadows_destroy(shadows);
    emitters_free(&emitters);
    free(hidden);
    free(reflected);
    free(sees);
    free(emitter_way);
    free(open_nodes);
    free(shown);
    free(without_emitters);
    display_mesh_free(&display);
    free(radiance);
    free(positions);
    patch_material_lookup_destroy(lookup);
    rad_patch_inputs_destroy(built_inputs);
    free(shaded);
    free(first_triangle);
    return status;
}

rad_status rad_render(const rad_mesh *mesh, const rad_rgb *B, const rad_camera *camera,
                      const rad_render_options *options, rad_image *image, rad_error *error)
{
    rad_render_options defaults = {0};
    if (!options)
        options = &defaults;
    if (options->inputs && options->inputs->n != mesh->patch_count)
        return rad_fail(error, RAD_ERR_INVALID,
                        "render: the patch inputs are for %u patches, the mesh has %u",
                        options->inputs->n, mesh->patch_count);
    if (options->direct_light == RAD_DIRECT_SOLUTION || options->threads < 0)
        return render_mesh(mesh, B, NULL, camera, options, image, error);
    /* the light at the vertices is shown on a finer mesh where the emitters' shadows bend
     * it (light_refine.h) */
    light_refined refined;
    rad_status status = light_refine(options->scene, mesh, B, options->inputs,
                                     options->threads > 0 ? options->threads
                                                          : omp_get_max_threads(),
                                     &refined, error);
    status = ranks_agree(status, "render", error);
    if (status == RAD_OK && refined.mesh) {
        rad_render_options finer = *options;
        finer.inputs = refined.inputs;
        status = render_mesh(refined.mesh, refined.B, refined.parents, camera, &finer, image,
                             error);
    } else if (status == RAD_OK)
        status = render_mesh(mesh, B, NULL, camera, options, image, error);
    light_refined_free(&refined);
    return status;
}
