/*
 * light_refine.c - a finer mesh to show the light on, where the emitters' shadows bend it
 * (light_refine.h).
 */
#include "render/light_refine.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/edge_key.h"
#include "core/error.h"
#include "core/random.h"
#include "core/rgb.h"
#include "core/vec3.h"
#include "lights/emitters.h"
#include "render/emitter_light.h"
#include "render/reflector_planes.h"
#include "render/vertex_light.h"
#include "render/vertex_radiance.h"
#include "solve/patch_inputs.h"
#include "trace/ray.h"

#define OPENNESS_STREAM 0x6F70656Eull /* the openness rays' random numbers, their own */

enum { SEES_NONE, SEES_PART, SEES_ALL };

/* Why a patch is split (split_patches): not; for the emitters' light or at a crease (its
 * new vertices take their gathered light from its corners unless its corners' openness
 * differs); for the light a region reflects (its new vertices gather theirs); a crease
 * waiting for the budget the shadows leave, a reflector's plane for its own. */
enum { SPLIT_NOT, SPLIT_EMITTERS, SPLIT_CREASE, SPLIT_REFLECTED, SPLIT_PLANE };

/* What a mesh being refined knows of each vertex: the share of the emitters' light that
 * reaches it (its point, as vertex_light takes it) and how that share reads. */
typedef struct vertex_share {
    double share;
    double open; /* the mean of min(1, t / reach) over cosine rays: 1 in the open, less
                    next to a concave crease or a contact */
    uint8_t sees;
} vertex_share;

typedef struct refine_state {
    const rad_scene *scene;
    const emitter_set *set;
    const rad_tracer *occluders;
    double leave;
    int threads;
    double reach; /* the distance a crease is felt at (openness) */
} refine_state;

/* share[v] for the vertices from `first` on. */
static bool measure_shares(const refine_state *st, const rad_mesh *mesh, uint32_t first,
                           vertex_share *share)
{
    uint32_t n = mesh->vertex_count;
    vertex_frame *frame = rad_alloc_array(n ? n : 1, sizeof(*frame));
    rad_ray *rays = rad_alloc_array((size_t)st->threads * LIGHT_REFINE_PROBES, sizeof(*rays));
    rad_rgb *values = rad_alloc_array((size_t)st->threads * LIGHT_REFINE_PROBES, sizeof(*values));
    uint8_t *blocked = rad_alloc_array((size_t)st->threads * LIGHT_REFINE_PROBES, 1);
    rad_hit *hits = rad_alloc_array((size_t)st->threads * LIGHT_REFINE_PROBES, sizeof(*hits));
    double *cosines = rad_alloc_array((size_t)st->threads * LIGHT_REFINE_PROBES, sizeof(double));
    bool ok = frame && rays && values && blocked && hits && cosines;
    if (ok) {
        vertex_frames(mesh, NULL, frame);
#pragma omp parallel for schedule(dynamic, 64) num_threads(st->threads)
        for (int64_t v = first; v < (int64_t)n; v++) {
            const vertex_frame *f = &frame[v];
            share[v] = (vertex_share){0, 1, SEES_NONE};
            if (!(f->weight > 0))
                continue;
            size_t base = (size_t)omp_get_thread_num() * LIGHT_REFINE_PROBES;
            rad_vec3 nv = v3_normalize(f->normal);
            rad_vec3 x = v3_add(mesh->vertices[v], v3_scale(f->inward, VERTEX_INWARD / f->weight));
            double open = 1;
            if (st->reach > 0) {
                rad_rng rng = rad_rng_seed(OPENNESS_STREAM, (uint64_t)v, 0);
                emitter_cosine_rays(x, nv, 2 * f->behind + st->leave, LIGHT_REFINE_PROBES, &rng,
                                    &rays[base], &cosines[base]);
                rad_tracer_intersect(st->occluders, &rays[base], LIGHT_REFINE_PROBES, &hits[base]);
                double sum = 0;
                for (uint32_t k = 0; k < LIGHT_REFINE_PROBES; k++)
                    sum += hits[base + k].triangle == RAD_NO_HIT
                               ? 1
                               : fmin(1, hits[base + k].t / st->reach);
                open = sum / LIGHT_REFINE_PROBES;
            }
            share[v].open = open;
            uint32_t count = emitter_light_rays_by_triangle(
                st->set, st->scene, x, nv, 2 * f->behind + st->leave, LIGHT_REFINE_PROBES, 0.5,
                0.5, 0.5, 0, &rays[base], &values[base]);
            rad_tracer_occluded(st->occluders, &rays[base], count, &blocked[base]);
            double all = 0, through = 0;
            for (uint32_t k = 0; k < count; k++) {
                double y = rgb_luminance(values[base + k]);
                all += y;
                through += blocked[base + k] ? 0 : y;
            }
            if (!(all > 0))
                continue;
            double s = through / all;
            share[v] = (vertex_share){s, open, s >= 1 ? SEES_ALL : s > 0 ? SEES_PART : SEES_NONE};
        }
    }
    free(frame);
    free(rays);
    free(values);
    free(blocked);
    free(hits);
    free(cosines);
    return ok;
}

/* Patch q's irradiance in solution B, (B - E) / rho in luminance (0 for a black one). */
static double patch_irradiance(const rad_rgb *B, const rad_patch_inputs *inputs, uint32_t q)
{
    double albedo = rgb_luminance(inputs->albedo[q]);
    return albedo > 0
               ? rgb_luminance(rgb_max0(rgb_add(B[q], rgb_scale(inputs->exitance[q], -1)))) /
                     albedo
               : 0;
}

/* The patch's longest edge. */
static double longest_edge(const rad_patch *patch, const rad_vec3 *vertices)
{
    double longest = 0;
    for (uint32_t k = 0; k < patch->vertex_count; k++)
        longest = fmax(longest, v3_length(v3_sub(vertices[patch->vertex[(k + 1) %
                                                                        patch->vertex_count]],
                                                 vertices[patch->vertex[k]])));
    return longest;
}

/* Whether the light bends inside the patch: 1 where its corners read the emitters' light
 * differently, else 2 where their openness differs (a crease or a contact the reflected
 * light bends at), else 0. */
static int bends(const rad_patch *patch, const vertex_share *share)
{
    double lo = INFINITY, hi = -INFINITY, open_lo = INFINITY, open_hi = -INFINITY;
    bool none = false, part = false, all = false;
    for (uint32_t k = 0; k < patch->vertex_count; k++) {
        const vertex_share *s = &share[patch->vertex[k]];
        lo = fmin(lo, s->share);
        hi = fmax(hi, s->share);
        open_lo = fmin(open_lo, s->open);
        open_hi = fmax(open_hi, s->open);
        none |= s->sees == SEES_NONE;
        part |= s->sees == SEES_PART;
        all |= s->sees == SEES_ALL;
    }
    if ((all && (none || part)) || (none && part) || hi - lo > LIGHT_REFINE_SHARE)
        return 1;
    return open_hi - open_lo > LIGHT_REFINE_OPEN ? 2 : 0;
}

/* Whether the light the surfaces around reflect bends inside the patch: its corners'
 * openness differs (a crease or a contact). Where it does not, a vertex added inside the
 * patch takes its gathered light from the patch's corners (vertex_parents), as the patch
 * unsplit would show it: only the emitters' light is computed there. */
static bool reflected_bends(const rad_patch *patch, const vertex_share *share)
{
    double lo = INFINITY, hi = -INFINITY;
    for (uint32_t k = 0; k < patch->vertex_count; k++) {
        lo = fmin(lo, share[patch->vertex[k]].open);
        hi = fmax(hi, share[patch->vertex[k]].open);
    }
    return hi - lo > LIGHT_REFINE_OPEN;
}

/* The midpoint vertex of edge (a, b), made once per edge (open addressing on the key). */
typedef struct midpoints {
    uint64_t *key;
    uint32_t *vertex;
    size_t mask;
} midpoints;

static uint32_t midpoint(midpoints *table, rad_mesh *mesh, vertex_parents *parents, uint32_t a,
                         uint32_t b)
{
    uint64_t key = edge_key(a, b);
    for (size_t slot = edge_key_hash(key) & table->mask;; slot = (slot + 1) & table->mask) {
        if (table->key[slot] == key)
            return table->vertex[slot];
        if (table->key[slot] == UINT64_MAX) {
            table->key[slot] = key;
            uint32_t v = mesh->vertex_count++;
            mesh->vertices[v] = v3_scale(v3_add(mesh->vertices[a], mesh->vertices[b]), 0.5);
            parents[v] = (vertex_parents){{a, b, 0, 0}, 2};
            table->vertex[slot] = v;
            return v;
        }
    }
}

/* A piece of `patch` with these corners: its area and centroid from them (a quad as two
 * triangles), the rest the patch's. */
static rad_patch piece(const rad_patch *patch, const rad_mesh *mesh, const uint32_t *corner,
                       uint32_t count)
{
    rad_patch out = *patch;
    out.vertex_count = count;
    memcpy(out.vertex, corner, count * sizeof(*corner));
    double area = 0;
    rad_vec3 centre = v3(0, 0, 0);
    for (uint32_t k = 1; k + 1 < count; k++) {
        rad_vec3 a = mesh->vertices[corner[0]], b = mesh->vertices[corner[k]],
                 c = mesh->vertices[corner[k + 1]];
        double t = 0.5 * v3_length(v3_cross(v3_sub(b, a), v3_sub(c, a)));
        area += t;
        centre = v3_add(centre, v3_scale(v3_add(a, v3_add(b, c)), t / 3));
    }
    out.area = area;
    out.centroid = area > 0 ? v3_scale(centre, 1 / area) : patch->centroid;
    return out;
}

/* The next mesh: each patch marked in `split` in four (in its place, so the twins still
 * come last), *parent updated to the new patches and *parents to the new vertices. */
static rad_status split_patches(const rad_mesh *mesh, const uint8_t *split, uint32_t splits,
                                const vertex_share *share, uint32_t **parent,
                                vertex_parents **parents, rad_mesh **out, rad_error *error)
{
    rad_mesh *next = rad_alloc_array(1, sizeof(*next));
    midpoints table = {0};
    size_t slots = 16;
    while (slots < 8 * (size_t)splits)
        slots *= 2;
    uint32_t *new_index = rad_alloc_array(mesh->patch_count ? mesh->patch_count : 1,
                                          sizeof(*new_index));
    uint32_t patches = mesh->patch_count + 3 * splits;
    uint32_t *next_parent = rad_alloc_array(patches ? patches : 1, sizeof(*next_parent));
    vertex_parents *grown = rad_resize_array(*parents, (size_t)mesh->vertex_count +
                                                           5 * (size_t)splits,
                                             sizeof(*grown));
    if (grown)
        *parents = grown;
    if (next) {
        *next = *mesh;
        next->vertices = rad_alloc_array((size_t)mesh->vertex_count + 5 * (size_t)splits,
                                         sizeof(*next->vertices));
        next->patches = rad_alloc_array(patches ? patches : 1, sizeof(*next->patches));
    }
    table.key = rad_alloc_array(slots, sizeof(*table.key));
    table.vertex = rad_alloc_array(slots, sizeof(*table.vertex));
    table.mask = slots - 1;
    if (!next || !next->vertices || !next->patches || !table.key || !table.vertex ||
        !new_index || !next_parent || !grown) {
        rad_mesh_destroy(next);
        free(table.key);
        free(table.vertex);
        free(new_index);
        free(next_parent);
        return rad_fail(error, RAD_ERR_NOMEM, "out of memory for the light's finer mesh");
    }
    memset(table.key, 0xff, slots * sizeof(*table.key));
    memcpy(next->vertices, mesh->vertices, mesh->vertex_count * sizeof(*mesh->vertices));
    uint32_t made = 0;
    for (uint32_t p = 0; p < mesh->patch_count; p++) {
        const rad_patch *patch = &mesh->patches[p];
        new_index[p] = made;
        if (!split[p]) {
            next_parent[made] = (*parent)[p];
            next->patches[made++] = *patch;
            continue;
        }
        const uint32_t *v = patch->vertex;
        const bool gathers = split[p] == SPLIT_REFLECTED || reflected_bends(patch, share);
        uint32_t m[4];
        for (uint32_t k = 0; k < patch->vertex_count; k++) {
            m[k] = midpoint(&table, next, grown, v[k], v[(k + 1) % patch->vertex_count]);
            if (gathers) /* (an edge's midpoint gathers when either side's patch bends) */
                grown[m[k]].count = 0;
        }
        uint32_t corners[4][4];
        uint32_t count;
        if (patch->vertex_count == 4) {
            uint32_t c = next->vertex_count++;
            next->vertices[c] = v3_scale(
                v3_add(v3_add(mesh->vertices[v[0]], mesh->vertices[v[1]]),
                       v3_add(mesh->vertices[v[2]], mesh->vertices[v[3]])),
                0.25);
            grown[c] = (vertex_parents){{v[0], v[1], v[2], v[3]}, gathers ? 0 : 4};
            const uint32_t q[4][4] = {{v[0], m[0], c, m[3]},
                                      {m[0], v[1], m[1], c},
                                      {c, m[1], v[2], m[2]},
                                      {m[3], c, m[2], v[3]}};
            memcpy(corners, q, sizeof(q));
            count = 4;
        } else {
            const uint32_t t[4][4] = {{v[0], m[0], m[2], 0},
                                      {m[0], v[1], m[1], 0},
                                      {m[2], m[1], v[2], 0},
                                      {m[0], m[1], m[2], 0}};
            memcpy(corners, t, sizeof(t));
            count = 3;
        }
        for (uint32_t k = 0; k < 4; k++) {
            next_parent[made] = (*parent)[p];
            next->patches[made++] = piece(patch, next, corners[k], count);
        }
    }
    next->patch_count = made;
    for (uint32_t p = 0; p < made; p++)
        if (next->patches[p].twin)
            next->patches[p].twin = 1 + new_index[next->patches[p].twin - 1];
    free(table.key);
    free(table.vertex);
    free(new_index);
    free(*parent);
    *parent = next_parent;
    *out = next;
    return RAD_OK;
}

/* The solution and the patch inputs on the finer mesh: each piece its patch's values
 * (they are per unit area), its own area. */
static rad_status carry_solution(const rad_mesh *fine, const uint32_t *parent, const rad_rgb *B,
                                 const rad_patch_inputs *inputs, light_refined *out,
                                 rad_error *error)
{
    uint32_t n = fine->patch_count;
    rad_patch_inputs *in = patch_inputs_alloc(n);
    out->B = rad_alloc_array(n, sizeof(*out->B));
    out->inputs = in;
    if (!out->B || !in)
        return rad_fail(error, RAD_ERR_NOMEM, "out of memory for the light's finer mesh");
    for (uint32_t p = 0; p < n; p++) {
        uint32_t q = parent[p];
        out->B[p] = B[q];
        in->area[p] = fine->patches[p].area;
        in->albedo[p] = inputs->albedo[q];
        in->exitance[p] = inputs->exitance[q];
        in->direct[p] = inputs->direct[q];
        in->direct_sharp[p] = inputs->direct_sharp[q];
        in->source[p] = inputs->source[q];
    }
    return RAD_OK;
}

rad_status light_refine(const rad_scene *scene, const rad_mesh *mesh, const rad_rgb *B,
                        const rad_patch_inputs *inputs, int threads, light_refined *out,
                        rad_error *error)
{
    *out = (light_refined){0};
    /* at most as many patches again for the emitters' light, and half as many for the
     * creases (or what the shadows left), and an eighth for the reflectors' planes; under
     * a memory budget no more than lets the whole finer mesh and the light at its vertices
     * (which comes after) fit three quarters of what is left: the finer mesh is an extra,
     * given up before the light, the planes' share first */
    size_t budget = (size_t)mesh->patch_count + mesh->patch_count / LIGHT_REFINE_CREASE_PART;
    size_t plane_budget = mesh->patch_count / LIGHT_REFINE_PLANE_PART;
    uint64_t left = rad_memory_budget_left();
    if (left != UINT64_MAX) {
        uint64_t fit = left / 4 * 3 / (LIGHT_REFINE_BYTES_PER_PATCH + VERTEX_LIGHT_BYTES_PER_PATCH);
        uint64_t room = fit > mesh->patch_count ? fit - mesh->patch_count : 0;
        if (room < budget)
            budget = (size_t)room;
        if (room - budget < plane_budget)
            plane_budget = (size_t)(room - budget);
    }
    if (!scene || !rad_scene_has_emitter(scene) || mesh->patch_count == 0 || budget < 3)
        return RAD_OK;
    emitter_set set = {0};
    reflector_set reflectors = {0};
    rad_tracer *occluders = NULL;
    rad_patch_inputs *built = NULL;
    rad_mesh *current = NULL;
    uint32_t *parent = rad_alloc_array(mesh->patch_count, sizeof(*parent));
    vertex_share *share = NULL;
    uint8_t *split = NULL;
    double *edge = NULL; /* per patch of the level: its longest edge */
    vertex_parents *parents = rad_alloc_array(mesh->vertex_count ? mesh->vertex_count : 1,
                                              sizeof(*parents));
    rad_status status = emitters_build(scene, &set, error);
    if (status == RAD_OK)
        status = rad_tracer_create_for_scene(RAD_TRACER_EMBREE, scene, &occluders, error);
    if (status == RAD_OK && !inputs) {
        status = rad_patch_inputs_build(scene, mesh, &built, error);
        inputs = built;
    }
    if (status == RAD_OK && plane_budget >= 3)
        status = reflectors_build(mesh, B, inputs, &reflectors, error);
    if (status != RAD_OK)
        goto done;
    if (!parent || !parents) {
        status = rad_fail(error, RAD_ERR_NOMEM, "out of memory for the light's finer mesh");
        goto done;
    }
    for (uint32_t p = 0; p < mesh->patch_count; p++)
        parent[p] = p;
    for (uint32_t v = 0; v < mesh->vertex_count; v++)
        parents[v] = (vertex_parents){{0, 0, 0, 0}, 0};
    refine_state st = {scene, &set, occluders, vertex_radiance_leave(mesh), threads, 0};
    /* no piece's edge shorter than the default mesh's (the dense solvers' patch size,
     * split by the shadow refinement's default levels) split LIGHT_REFINE_LEVELS times:
     * a mesh already that fine (the hierarchical solver's) is left as it is */
    const double patch_size = rad_default_patch_size(scene, RAD_SOLVER_JACOBI);
    const double smallest =
        0.99 * patch_size / (1u << (RAD_SHADOW_LEVELS_DEFAULT + LIGHT_REFINE_LEVELS));
    st.reach = LIGHT_REFINE_REACH * patch_size;
    /* the emitters' light first */
    size_t shadow_budget = mesh->patch_count;
    if (!(smallest > 0)) { /* 0: out of memory for the mesh plan */
        status = rad_fail(error, RAD_ERR_NOMEM, "out of memory for the light's finer mesh");
        goto done;
    }
    /* (a patch with next to no light of its own, as in the gap above a lamp, is not split
     * for a kink: a hundredth of the mean irradiance at least) */
    double dark = 0, area = 0;
    for (uint32_t q = 0; q < mesh->patch_count; q++) {
        dark += mesh->patches[q].area * patch_irradiance(B, inputs, q);
        area += mesh->patches[q].area;
    }
    dark = area > 0 ? 0.01 * dark / area : 0;
    const rad_mesh *at = mesh;
    uint32_t measured = 0;
    for (uint32_t level = 0; level < LIGHT_REFINE_LEVELS && (budget >= 3 || plane_budget >= 3);
         level++) {
        vertex_share *grown =
            rad_resize_array(share, at->vertex_count ? at->vertex_count : 1, sizeof(*share));
        uint8_t *marks = rad_resize_array(split, at->patch_count ? at->patch_count : 1, 1);
        double *edges =
            rad_resize_array(edge, at->patch_count ? at->patch_count : 1, sizeof(*edge));
        if (grown)
            share = grown;
        if (marks)
            split = marks;
        if (edges)
            edge = edges;
        if (!grown || !marks || !edges || !measure_shares(&st, at, measured, share)) {
            status = rad_fail(error, RAD_ERR_NOMEM, "out of memory for the light's finer mesh");
            goto done;
        }
        measured = at->vertex_count;
        /* the patches that may split (one-sided, not yet at the finest), marked first:
         * how many there are sets how many regions each is tested against */
        uint32_t splits = 0, candidates = 0;
        for (uint32_t p = 0; p < at->patch_count; p++) {
            edge[p] = longest_edge(&at->patches[p], at->vertices);
            split[p] = at->patches[p].twin == 0 && edge[p] >= 2 * smallest;
            candidates += split[p];
        }
        const uint32_t planes_tested =
            candidates ? (uint32_t)(REFLECTOR_TESTS / candidates) : 0;
        /* the patches the emitters' light bends in first, then those at creases and
         * where a reflecting region's plane crosses */
        for (uint32_t p = 0; p < at->patch_count; p++) {
            const rad_patch *patch = &at->patches[p];
            const bool candidate = split[p];
            int reason = candidate ? bends(patch, share) : 0;
            if (candidate && reason == 0 && plane_budget >= 3) {
                double H = patch_irradiance(B, inputs, parent[p]);
                if (H > dark &&
                    reflector_kink(&reflectors, planes_tested, patch, at->vertices, edge[p], H) >
                        LIGHT_REFINE_KINK)
                    reason = 3;
            }
            split[p] = reason == 1 && shadow_budget >= 3 && budget >= 3 ? SPLIT_EMITTERS
                       : reason == 1 || reason == 2                     ? SPLIT_CREASE
                       : reason == 3                                    ? SPLIT_PLANE
                                                                        : SPLIT_NOT;
            if (split[p] == SPLIT_EMITTERS) {
                splits++;
                budget -= 3;
                shadow_budget -= 3;
            }
        }
        for (uint32_t p = 0; p < at->patch_count; p++) {
            if (split[p] == SPLIT_CREASE && budget >= 3) {
                split[p] = SPLIT_EMITTERS;
                splits++;
                budget -= 3;
            } else if (split[p] == SPLIT_PLANE && plane_budget >= 3) {
                split[p] = SPLIT_REFLECTED;
                splits++;
                plane_budget -= 3;
            } else if (split[p] == SPLIT_CREASE || split[p] == SPLIT_PLANE) {
                split[p] = SPLIT_NOT;
            }
        }
        if (splits == 0)
            break;
        rad_mesh *next = NULL;
        status = split_patches(at, split, splits, share, &parent, &parents, &next, error);
        if (status != RAD_OK)
            goto done;
        rad_mesh_destroy(current);
        current = next;
        at = current;
    }
    if (current) {
        status = carry_solution(current, parent, B, inputs, out, error);
        out->mesh = current;
        out->parent = parent;
        out->parents = parents;
        current = NULL;
        parent = NULL;
        parents = NULL;
    }
done:
    if (status != RAD_OK)
        light_refined_free(out);
    rad_mesh_destroy(current);
    rad_patch_inputs_destroy(built);
    rad_tracer_destroy(occluders);
    emitters_free(&set);
    reflectors_free(&reflectors);
    free(parent);
    free(parents);
    free(share);
    free(split);
    free(edge);
    return status;
}

void light_refined_free(light_refined *refined)
{
    rad_mesh_destroy(refined->mesh);
    free(refined->B);
    free(refined->parent);
    free(refined->parents);
    rad_patch_inputs_destroy(refined->inputs);
    *refined = (light_refined){0};
}
