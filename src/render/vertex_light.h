/*
 * vertex_light.h - the light arriving at each mesh vertex, computed at the point rather
 * than averaged over patches (internal): the emitters' direct irradiance (1024 shadow rays
 * shared evenly by the emitting triangles, 128 first: the share that gets through of their
 * exact unshadowed irradiance when emitter_unshadowed_exact, else MIS with 512 cosine
 * rays), the sharp sources' (one shadow ray each) and the irradiance gathered from the
 * solution's reflected light (a final gather: VERTEX_GATHER_RAYS cosine-weighted rays
 * meeting (B - E) / pi, the sky where they leave; or fewer meeting a change of that light:
 * vertex_radiance.h). The default render interpolates these point values over the display
 * triangles (the emitters' light in penumbrae excepted: radiosity_render.c), so soft
 * shadows, contact shadows and the light next to creases follow the light itself, not
 * patch means smeared over neighbours.
 * Each vertex is evaluated a tenth of the way toward the centre of the patches that share
 * it (those `hidden` does not mark), on their side, so a vertex on a crease or a contact
 * takes the open side's value.
 * It does not reconstruct or draw (radiosity_render.c does).
 */
#ifndef RAD_RENDER_VERTEX_LIGHT_H
#define RAD_RENDER_VERTEX_LIGHT_H

#include "lights/emitters.h"
#include "radiosity.h"
#include "render/gather.h"

/* A vertex's point: this share of the way to its patches' mean centre. On a crease or a
 * contact the light changes fastest next to the vertex (a contact shadow's foot), so its
 * exact limit there, interpolated linearly over the patch, would pull the patch's values
 * down; a point a tenth of the way in stands for the vertex's neighbourhood. Measured on
 * the Cornell box at 128 x 128 against the path tracer (block / pixel relative RMSE):
 * 1e-3 1.57 % / 1.95 %, 0.1 1.17 % / 1.72 %, 0.25 1.20 % / 1.70 %, 0.5 1.60 % / 1.83 %. */
#define VERTEX_INWARD 0.1

/* Each vertex's side (its visible patches' normal: a region is planar), the way into those
 * patches (area-weighted: the point is vertex + VERTEX_INWARD x inward / weight), how far
 * their cells may lie behind the input triangles, and their area (0: a vertex of hidden
 * patches alone). */
typedef struct vertex_frame {
    rad_vec3 normal, inward;
    double behind, weight;
} vertex_frame;

/* frame[v] for the mesh's vertices, patches marked in `hidden` (NULL: none) left out. */
void vertex_frames(const rad_mesh *mesh, const uint8_t *hidden, vertex_frame *frame);

/* What a vertex's shadow rays toward the emitters found: all blocked (or none traced),
 * some, or none blocked. A display triangle whose corners disagree, or one of which sees
 * a part, lies in a penumbra: the default render computes the emitters' light at its
 * pixels (radiosity_render.c). */
enum { VERTEX_SEES_NONE, VERTEX_SEES_PART, VERTEX_SEES_ALL };

/* Where a vertex's gathered light comes from: count 0, its own gather; else the mean of
 * the gathered light of `count` (2 or 4) vertices of lower index (light_refine.h: a vertex
 * it added where only the emitters' light bends, whose reflected light is as linear as
 * its patch's). */
typedef struct vertex_parents {
    uint32_t vertex[4];
    uint32_t count;
} vertex_parents;

/* What vertex_light computes and with what. */
typedef struct vertex_light_job {
    const emitter_set *emitters; /* their direct light, traced against `occluders` (the
                                    scene's triangles); empty: none */
    const light_set *sharp;      /* NULL, or the sharp sources (point, spot, luminaire,
                                    sun: one shadow ray each) */
    const rad_scene *scene;
    const rad_mesh *mesh;
    const rad_tracer *occluders;
    const gather_view *view;     /* what the gather rays meet */
    uint32_t gather_rays;        /* per vertex: VERTEX_GATHER_RAYS, or fewer for a
                                    correction (a view of a change: gather.h) */
    const uint8_t *hidden;       /* patches no one sees (NULL: none) */
    const vertex_parents *parents; /* per vertex (NULL: every vertex gathers) */
    uint8_t *sees;               /* out, per vertex (NULL: not asked): how much of the
                                    emitters' light its shadow rays found (VERTEX_SEES_*) */
    double leave;                /* how far rays start off a surface */
    uint64_t seed;
    int threads;
    bool over_ranks; /* with several MPI ranks, collective: each rank lights its share of
                        the vertices (chunks of VERTEX_RANK_CHUNK dealt out in turn) and
                        every rank gets every vertex's light, bitwise the serial values;
                        every rank returns the same status */
} vertex_light_job;

/* Final-gather rays per vertex (the first gather, from the solution's patches): a square,
 * so that every ray has its stratum (40 x 40). Their noise is most of what is left of the
 * default render's error: two seeds' Cornell renders at 256 x 256 differ by 0.70 % on
 * blocks with 1024 rays, 0.52 % with 1600, 0.33 % with 4096. Against the 16384-spp
 * reference (block / pixel, render seconds on 2 cores): 1024 rays 0.838 / 1.102 %, 1.23 s;
 * 1296 0.826 / 1.062 %, 1.50 s; 1600 0.780 / 1.046 %, 1.62 s; 2025 0.774 / 1.022 %, 1.84 s. */
#define VERTEX_GATHER_RAYS 1600u

/* Per mesh vertex v (mesh->vertex_count values): direct[v], the emitters' direct
 * irradiance, sharp[v] the sharp sources', and gathered[v], the irradiance the view's
 * reflected light brings. direct and sharp may be NULL: not asked for, nor traced. A
 * vertex of hidden patches alone gets 0. Deterministic per seed for any thread and rank
 * count. */
rad_status vertex_light(const vertex_light_job *job, rad_rgb *direct, rad_rgb *sharp,
                        rad_rgb *gathered, rad_error *error);

#endif
