/*
 * vertex_light.c - the light arriving at each mesh vertex (vertex_light.h).
 */
#include "render/vertex_light.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>

#include "core/alloc.h"
#include "core/error.h"
#include "core/order.h"
#include "core/random.h"
#include "core/rgb.h"
#include "core/vec3.h"
#include "parallel/ranks.h"
#include "render/emitter_light.h"
#include "trace/ray.h"

#define VERTEX_EMITTER_SAMPLES 1024u /* light samples per vertex */
#define VERTEX_COSINE_RAYS 512u     /* their MIS partners: cosine rays toward the emitters */
/* With the emitters' unshadowed light exact, a vertex first traces this share of its light
 * samples (128: each emitting triangle's first Halton points, spread over it); when all
 * get through or none does, that is the vertex's answer, else it traces all 1024. An
 * occluder that the first 128 all miss is missed: one narrower than about 1/11 of the
 * emitter's width. On the Cornell box at 256 x 256 most vertices see the whole light or
 * none: the render 1.50 -> 1.23 s, its error the same (block / pixel 0.841 / 1.104 % ->
 * 0.838 / 1.102 % against the 16384-spp reference). With penumbra_at_pixels (the default
 * render) a vertex that sees a part keeps the first 128 too: 3837 of the Cornell box's
 * 10,878 lit vertices, 3.4 M shadow rays fewer; 256 x 256, seeds 1-3, block / pixel
 * 0.472 / 0.817 % -> 0.474 / 0.817 %, the render about 0.1 s shorter (4 interleaved runs:
 * 1.30, 1.40, 1.27, 1.63 -> 1.22, 1.16, 1.18, 1.32 s). */
/* A vertex whose first samples disagree takes the light behind the occluders exactly
 * where it can be had (emitter_shadows.h) instead of the rest: on a furnished room of
 * 9,942 triangles exact light at every vertex had cost 0.4-1 s more than these samples;
 * where they agree they are cheaper. */
#define VERTEX_SHADOW_FIRST 8u

#define VERTEX_RANK_CHUNK 64u       /* over ranks: vertices dealt out in turn, this many at
                                       a time */
/* Over ranks, what each vertex's light is shared as: direct, sharp, gathered (3 doubles
 * each) and whether it is buried with what it sees (buried + 2 x sees). */
#define VERTEX_SHARED_DOUBLES 10u

/* The rank (of `ranks`) that lights vertex v. */
static uint32_t vertex_rank(uint32_t v, uint32_t ranks)
{
    return (v / VERTEX_RANK_CHUNK) % ranks;
}

/* Over ranks: every rank's vertices' direct, sharp, gathered and buried to every rank
 * (each rank filled its own; `lit` false: it could not). False, on every rank, when any
 * could not or ran out of memory here. Collective. */
static bool share_vertices(uint32_t n, bool lit, rad_rgb *direct, rad_rgb *sharp,
                           rad_rgb *gathered, uint32_t *buried, uint8_t *sees)
{
    const uint32_t ranks = (uint32_t)ranks_count(), rank = (uint32_t)ranks_rank();
    uint64_t *counts = rad_alloc_array(ranks, sizeof(*counts));
    double *mine = NULL, *all = rad_alloc_array((size_t)n * VERTEX_SHARED_DOUBLES + 1,
                                                sizeof(double));
    if (counts)
        for (uint32_t v = 0; v < n; v++)
            counts[vertex_rank(v, ranks)] += VERTEX_SHARED_DOUBLES;
    if (counts)
        mine = rad_alloc_array(counts[rank] + 1, sizeof(double));
    bool ok = lit && counts && mine && all;
    if (ranks_failures(!ok) > 0) {
        free(counts);
        free(mine);
        free(all);
        return false;
    }
    size_t at = 0;
    for (uint32_t v = 0; v < n; v++)
        if (vertex_rank(v, ranks) == rank) {
            double *d = &mine[at];
            const rad_rgb none = {0, 0, 0}, a = direct ? direct[v] : none,
                          b = sharp ? sharp[v] : none;
            d[0] = a.r, d[1] = a.g, d[2] = a.b;
            d[3] = b.r, d[4] = b.g, d[5] = b.b;
            d[6] = gathered[v].r, d[7] = gathered[v].g, d[8] = gathered[v].b;
            d[9] = buried[v] + 2.0 * (sees ? sees[v] : 0);
            at += VERTEX_SHARED_DOUBLES;
        }
    ranks_share_parts(mine, all, counts);
    /* rank r's part holds its vertices in order: walk each part with its own cursor */
    for (uint32_t r = 1; r < ranks; r++)
        counts[r] += counts[r - 1];
    for (uint32_t r = ranks; r-- > 1;)
        counts[r] = counts[r - 1];
    counts[0] = 0;
    for (uint32_t v = 0; v < n; v++) {
        const double *d = &all[counts[vertex_rank(v, ranks)]];
        counts[vertex_rank(v, ranks)] += VERTEX_SHARED_DOUBLES;
        if (direct)
            direct[v] = (rad_rgb){d[0], d[1], d[2]};
        if (sharp)
            sharp[v] = (rad_rgb){d[3], d[4], d[5]};
        gathered[v] = (rad_rgb){d[6], d[7], d[8]};
        buried[v] = (uint32_t)d[9] % 2;
        if (sees)
            sees[v] = (uint8_t)((uint32_t)d[9] / 2);
    }
    free(counts);
    free(mine);
    free(all);
    return true;
}

#define VERTEX_STREAM 0xE3177E3ull

void vertex_frames(const rad_mesh *mesh, const uint8_t *hidden, vertex_frame *frame)
{
    for (uint32_t v = 0; v < mesh->vertex_count; v++)
        frame[v] = (vertex_frame){v3(0, 0, 0), v3(0, 0, 0), 0, 0};
    for (uint32_t p = 0; p < mesh->patch_count; p++) {
        const rad_patch *patch = &mesh->patches[p];
        if (hidden && hidden[p])
            continue; /* seen by no one: its vertices' values come from the others */
        for (uint32_t k = 0; k < patch->vertex_count; k++) {
            vertex_frame *f = &frame[patch->vertex[k]];
            f->normal = v3_add(f->normal, v3_scale(patch->normal, patch->area));
            f->inward = v3_add(f->inward, v3_scale(v3_sub(patch->centroid,
                                                          mesh->vertices[patch->vertex[k]]),
                                                   patch->area));
            f->behind = fmax(f->behind, patch->behind);
            f->weight += patch->area;
        }
    }
}

/* What `through` unblocked shadow rays of `count` say a vertex sees. */
static uint8_t sees_of(uint32_t through, uint32_t count)
{
    return through == 0 ? VERTEX_SEES_NONE : through == count ? VERTEX_SEES_ALL : VERTEX_SEES_PART;
}

/* Vertex v's three values (direct and sharp: where asked for). */
static void vertex_light_set(rad_rgb *direct, rad_rgb *sharp, rad_rgb *gathered, uint32_t v,
                             rad_rgb d, rad_rgb s, rad_rgb g)
{
    if (direct)
        direct[v] = d;
    if (sharp)
        sharp[v] = s;
    gathered[v] = g;
}

/* A vertex whose point lies inside a closed object (a floor patch that runs under a box
 * standing on it: most of its gather rays meet the backs of the box's one-sided faces)
 * has no light of its own, yet its patch shows outside the box; interpolating its zero
 * would darken that visible part toward the box's foot. It takes instead the mean of the
 * vertices it shares a visible patch with that are not buried (left as it is when it has
 * none). Buried means that 7/8 of its gather rays met the back of a one-sided surface.
 * Measured on the Cornell box at 128 x 128 against the 65536-spp reference (block / pixel
 * relative RMSE): the CLI's mesh 0.97 % / 1.57 % -> 0.94 % / 1.34 %; without the proximity
 * refinement 1.02 % / 1.57 % -> 0.98 % / 1.34 %; the error it took away sat along the
 * blocks' feet on the floor. An emitter's back counts too (it was left out at first): a
 * ceiling vertex in the gap above a lamp's back, kept dark, darkened the visible ceiling
 * around the lamp by interpolation, a ring 1-3 pixels wide at 256 x 256 down to -51 %
 * of the reference; counting it, block / pixel 1.164 % / 1.351 % -> 1.143 % / 1.345 %
 * against a 16384-spp 256 x 256 reference, the ring's rows within 4 %. */
static void buried_from_neighbours(const rad_mesh *mesh, const uint8_t *hidden,
                                   const vertex_parents *parents, uint32_t *buried,
                                   rad_rgb *direct, rad_rgb *sharp, rad_rgb *gathered)
{
    /* buried[v]: 0 open, 1 buried with no open neighbour yet, 1 + m with m of them */
    for (uint32_t p = 0; p < mesh->patch_count; p++) {
        const rad_patch *patch = &mesh->patches[p];
        if (hidden && hidden[p])
            continue;
        for (uint32_t k = 0; k < patch->vertex_count; k++) {
            uint32_t v = patch->vertex[k];
            for (uint32_t j = 0; buried[v] && j < patch->vertex_count; j++) {
                uint32_t u = patch->vertex[j];
                if (buried[u] || (parents && parents[u].count))
                    continue; /* (one whose gather comes later from its parents) */
                if (buried[v] == 1) /* its first open neighbour: the mean starts */
                    vertex_light_set(direct, sharp, gathered, v, (rad_rgb){0, 0, 0},
                                     (rad_rgb){0, 0, 0}, (rad_rgb){0, 0, 0});
                if (direct)
                    rgb_add_to(&direct[v], direct[u]);
                if (sharp)
                    rgb_add_to(&sharp[v], sharp[u]);
                rgb_add_to(&gathered[v], gathered[u]);
                buried[v]++;
            }
        }
    }
    for (uint32_t v = 0; v < mesh->vertex_count; v++)
        if (buried[v] > 1) {
            double count = buried[v] - 1;
            if (direct)
                direct[v] = rgb_scale(direct[v], 1 / count);
            if (sharp)
                sharp[v] = rgb_scale(sharp[v], 1 / count);
            gathered[v] = rgb_scale(gathered[v], 1 / count);
        }
}

/* The area around a vertex whose gather is given all of its rays (gather_rays_for): the
 * GATHER_FULL_SHARE quantile of the gathering vertices' areas (vertex_frame.weight, the
 * sum of their patches' areas): about a whole patch's vertex away from the refined parts.
 * 0 when no vertex gathers; -1 when out of memory. */
static double gather_full_area(const vertex_frame *frame, const vertex_parents *parents,
                               uint32_t n)
{
    uint32_t count = 0;
    for (uint32_t v = 0; v < n; v++)
        count += frame[v].weight > 0 && !(parents && parents[v].count);
    if (count == 0)
        return 0;
    double *areas = rad_alloc_array(count, sizeof(*areas));
    if (!areas)
        return -1;
    uint32_t at = 0;
    for (uint32_t v = 0; v < n; v++)
        if (frame[v].weight > 0 && !(parents && parents[v].count))
            areas[at++] = frame[v].weight;
    qsort(areas, count, sizeof(*areas), rad_compare_doubles);
    double full = areas[(uint32_t)(GATHER_FULL_SHARE * (count - 1))];
    free(areas);
    return full;
}

/* Vertex v's gather rays: `most` times the square root of its area's share of `full`, up
 * to the next power of two, at least most / GATHER_FEWEST_PART. */
static uint32_t gather_rays_for(double area, double full, uint32_t most)
{
    const uint32_t fewest = most / GATHER_FEWEST_PART ? most / GATHER_FEWEST_PART : 1;
    if (!(area < full))
        return most;
    double wanted = most * sqrt(area / full);
    uint32_t rays = fewest;
    while (rays < wanted && rays < most)
        rays *= 2;
    return rays < most ? rays : most;
}

rad_status vertex_light(const vertex_light_job *job, rad_rgb *direct, rad_rgb *sharp,
                        rad_rgb *gathered, rad_error *error)
{
    const rad_mesh *mesh = job->mesh;
    const emitter_set *set = job->emitters;
    const rad_scene *scene = job->scene;
    const gather_view *view = job->view;
    const light_set *sources = job->sharp;
    const int threads = job->threads;
    uint32_t n = mesh->vertex_count;
    const uint32_t ranks = job->over_ranks ? (uint32_t)ranks_count() : 1;
    const uint32_t rank = ranks > 1 ? (uint32_t)ranks_rank() : 0;
    const rad_rgb zero = {0, 0, 0};
    for (uint32_t v = 0; v < n; v++) {
        vertex_light_set(direct, sharp, gathered, v, zero, zero, zero);
        if (job->sees)
            job->sees[v] = VERTEX_SEES_NONE;
    }
    if (n == 0) /* (the same on every rank) */
        return RAD_OK;
    if (job->gather_rays == 0)
        return rad_fail(error, RAD_ERR_INVALID, "the light at the vertices: no gather rays");
    const bool emitters = set->count > 0 && direct; /* their light asked for */
    const bool exact = emitters && emitter_unshadowed_exact(set, scene);
    const uint32_t sharp_rays =
        sources && sharp ? light_set_capacity(sources, LIGHTS_SHARP, 0) : 0;
    const uint32_t samples = emitters ? VERTEX_EMITTER_SAMPLES : 0;
    const uint32_t gather = job->gather_rays;
    uint32_t capacity = samples > sharp_rays ? samples : sharp_rays; /* shadow rays */
    capacity = capacity ? capacity : 1;
    const uint32_t cosines_per_vertex =
        VERTEX_COSINE_RAYS > gather ? VERTEX_COSINE_RAYS : gather;
    vertex_frame *frame = rad_alloc_array(n, sizeof(*frame));
    rad_ray *rays = rad_alloc_array((size_t)threads * capacity, sizeof(*rays));
    rad_rgb *values = rad_alloc_array((size_t)threads * capacity, sizeof(*values));
    uint8_t *blocked = rad_alloc_array((size_t)threads * capacity, sizeof(*blocked));
    rad_ray *cosine_rays = rad_alloc_array((size_t)threads * cosines_per_vertex,
                                           sizeof(*cosine_rays));
    rad_hit *hits = rad_alloc_array((size_t)threads * cosines_per_vertex, sizeof(*hits));
    double *cosines = rad_alloc_array((size_t)threads * cosines_per_vertex, sizeof(*cosines));
    uint32_t *buried = rad_alloc_array(n ? n : 1, sizeof(*buried));
    bool ok = frame && rays && values && blocked && cosine_rays && hits && cosines && buried;
    double full_area = 0;
    if (ok) {
        vertex_frames(mesh, job->hidden, frame);
        full_area = gather_full_area(frame, job->parents, n);
        ok = full_area >= 0;
    }
    if (ok) {
        for (uint32_t v = 0; v < n; v++)
            buried[v] = 0;
#pragma omp parallel for schedule(dynamic, 64) num_threads(threads)
        for (int64_t v = 0; v < (int64_t)n; v++) {
            const vertex_frame *f = &frame[v];
            if (!(f->weight > 0) || vertex_rank((uint32_t)v, ranks) != rank)
                continue;
            int thread = omp_get_thread_num();
            rad_ray *light = &rays[(size_t)thread * capacity];
            rad_rgb *value = &values[(size_t)thread * capacity];
            uint8_t *shadowed = &blocked[(size_t)thread * capacity];
            rad_ray *cosine = &cosine_rays[(size_t)thread * cosines_per_vertex];
            rad_hit *hit = &hits[(size_t)thread * cosines_per_vertex];
            double *cos_x = &cosines[(size_t)thread * cosines_per_vertex];
            rad_rng rng = rad_rng_seed(job->seed ^ VERTEX_STREAM, (uint64_t)v, 0);
            double turn = rad_rng_uniform(&rng), shift1 = rad_rng_uniform(&rng),
                   shift2 = rad_rng_uniform(&rng);
            rad_vec3 nv = v3_normalize(f->normal);
            /* inside the vertex's patches (toward their mean centre): at a contact or a
             * crease the point is on the open side, as the patches are */
            rad_vec3 x = v3_add(mesh->vertices[v], v3_scale(f->inward, VERTEX_INWARD / f->weight));
            double off = 2 * f->behind + job->leave;
            rad_rgb sum = {0, 0, 0};
            if (exact) {
                /* the unshadowed light exactly, times the share of the samples' that gets
                 * through; a first 1/VERTEX_SHADOW_FIRST of them (each triangle's first
                 * Halton points) all through or all blocked settles it; else the light
                 * behind the occluders exactly (emitter_shadows.h), where it can be had,
                 * or all the samples */
                uint32_t tried = samples / VERTEX_SHADOW_FIRST, count = 0, through = 0;
                rad_rgb behind;
                bool settled = false;
                for (int round = 0; round < 2; round++) {
                    count = emitter_light_rays_by_triangle(set, scene, x, nv, off, tried, turn,
                                                           shift1, shift2, 0, light, value);
                    emitter_to_unshadowed(set, scene, x, nv, value, count);
                    rad_tracer_occluded(job->occluders, light, count, shadowed);
                    through = 0;
                    for (uint32_t k = 0; k < count; k++)
                        through += !shadowed[k];
                    if (tried == samples || through == 0 || through == count)
                        break;
                    if (job->shadows &&
                        emitter_shadows_irradiance(job->shadows, v3_add(x, v3_scale(nv, off)),
                                                   nv, EMITTER_SHADOWS_MAX_OCCLUDERS,
                                                   &behind)) {
                        settled = true;
                        break;
                    }
                    if (job->penumbra_at_pixels)
                        break;
                    tried = samples;
                }
                if (settled)
                    sum = behind;
                for (uint32_t k = 0; !settled && k < count; k++)
                    if (!shadowed[k])
                        rgb_add_to(&sum, value[k]);
                if (job->sees)
                    job->sees[v] = sees_of(through, count);
            } else if (emitters) {
                const double share = (double)VERTEX_COSINE_RAYS / samples;
                uint32_t count = emitter_light_rays_by_triangle(
                    set, scene, x, nv, off, samples, turn, shift1, shift2, share, light, value);
                emitter_cosine_rays(x, nv, off, VERTEX_COSINE_RAYS, &rng, cosine, cos_x);
                rad_tracer_occluded(job->occluders, light, count, shadowed);
                rad_tracer_intersect(job->occluders, cosine, VERTEX_COSINE_RAYS, hit);
                uint32_t through = 0;
                for (uint32_t k = 0; k < count; k++)
                    if (!shadowed[k]) {
                        rgb_add_to(&sum, value[k]);
                        through++;
                    }
                if (job->sees)
                    job->sees[v] = sees_of(through, count);
                for (uint32_t k = 0; k < VERTEX_COSINE_RAYS; k++)
                    rgb_add_to(&sum, emitter_cosine_value_weighted(set, scene, &cosine[k], &hit[k],
                                                                   cos_x[k], VERTEX_COSINE_RAYS,
                                                                   1 / share));
            }
            if (direct)
                direct[v] = sum;
            /* the sharp sources after the emitters' random numbers: theirs unchanged */
            if (sharp_rays > 0) {
                uint32_t count = light_set_rays(sources, LIGHTS_SHARP, x, nv, off, 0, 1, 0,
                                                &rng, light, value);
                rad_tracer_occluded(job->occluders, light, count, shadowed);
                rad_rgb lit = {0, 0, 0};
                for (uint32_t k = 0; k < count; k++)
                    if (!shadowed[k])
                        rgb_add_to(&lit, value[k]);
                sharp[v] = lit;
            }

            if (job->parents && job->parents[v].count)
                continue; /* its gathered light: its parents' mean, below */
            /* the gather: E = pi / N x the sum of the radiance met by N cosine rays */
            uint32_t count = gather_rays_for(f->weight, full_area, gather);
            if (job->shown && !job->shown[v]) {
                if (job->unshown_part == 0)
                    continue; /* no pixel shows its light */
                count = count / job->unshown_part ? count / job->unshown_part : 1;
            }
            emitter_cosine_rays(x, nv, off, count, &rng, cosine, cos_x);
            gather_trace(view, cosine, count, hit);
            rad_rgb seen = {0, 0, 0};
            uint32_t backs = 0; /* rays that met the back of a one-sided surface */
            for (uint32_t k = 0; k < count; k++) {
                rgb_add_to(&seen, gather_seen(view, &cosine[k], &hit[k]));
                if (hit[k].triangle != RAD_NO_HIT && !hit[k].front)
                    backs += !mesh->patches[view->patch_of[hit[k].triangle]].twin;
            }
            gathered[v] = rgb_scale(seen, RAD_PI / count);
            buried[v] = backs > count - count / 8; /* enclosed: 7/8 of the rays */
            if (buried[v] && job->sees) /* its light comes from its neighbours': mixed */
                job->sees[v] = VERTEX_SEES_PART;
        }
    }
    if (ranks > 1) /* every rank, whether its buffers were had or not */
        ok = share_vertices(n, ok, direct, sharp, gathered, buried, job->sees);
    if (ok) {
        buried_from_neighbours(mesh, job->hidden, job->parents, buried, direct, sharp,
                               gathered);
        for (uint32_t v = 0; job->parents && v < n; v++) /* parents come first */
            if (job->parents[v].count && frame[v].weight > 0) {
                rad_rgb mean = {0, 0, 0};
                for (uint32_t k = 0; k < job->parents[v].count; k++)
                    rgb_add_to(&mean, gathered[job->parents[v].vertex[k]]);
                gathered[v] = rgb_scale(mean, 1.0 / job->parents[v].count);
            }
    }
    free(frame);
    free(buried);
    free(rays);
    free(values);
    free(blocked);
    free(cosine_rays);
    free(hits);
    free(cosines);
    if (!ok)
        return rad_fail(error, RAD_ERR_NOMEM, "out of memory for the light at the vertices");
    return RAD_OK;
}
