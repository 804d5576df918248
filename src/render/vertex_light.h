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
#include "render/emitter_shadows.h"
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
    const emitter_shadows *shadows; /* NULL, or their light behind every occluder exactly
                                       (then no shadow rays where it can be had) */
    const light_set *sharp;      /* NULL, or the sharp sources (point, spot, luminaire,
                                    sun: one shadow ray each) */
    const rad_scene *scene;
    const rad_mesh *mesh;
    const rad_tracer *occluders;
    const gather_view *view;     /* what the gather rays meet */
    uint32_t gather_rays;        /* per vertex at most, a power of two: VERTEX_GATHER_RAYS,
                                    or fewer for a correction (a view of a change:
                                    gather.h); a vertex's share of them by its area */
    const uint8_t *hidden;       /* patches no one sees (NULL: none) */
    const vertex_parents *parents; /* per vertex (NULL: every vertex gathers) */
    uint8_t *sees;               /* out, per vertex (NULL: not asked): how much of the
                                    emitters' light its shadow rays found (VERTEX_SEES_*) */
    const uint8_t *shown;        /* per vertex, or NULL (all): whether a pixel may show it;
                                    a vertex none shows gathers with 1/unshown_part of its
                                    rays (its light still lights the second gather's
                                    field), or not at all when unshown_part is 0 */
    uint32_t unshown_part;
    bool penumbra_at_pixels;     /* with `sees`: a vertex that sees a part of the emitters'
                                    light is shown by no interpolation (every display
                                    triangle it is a corner of takes the emitters' light
                                    at its pixels), so its direct light only lights the
                                    second gather's field, and it keeps its first
                                    1/VERTEX_SHADOW_FIRST of the light samples */
    double leave;                /* how far rays start off a surface */
    uint64_t seed;
    int threads;
    bool over_ranks; /* with several MPI ranks, collective: each rank lights its share of
                        the vertices (chunks of VERTEX_RANK_CHUNK dealt out in turn) and
                        every rank gets every vertex's light, bitwise the serial values;
                        every rank returns the same status */
} vertex_light_job;

/* Final-gather rays per vertex (the first gather, from the solution's patches): a power of
 * two, so that they are a net of the scrambled Sobol points (emitter_cosine_rays). Their
 * noise is most of what is left of the default render's error. Cornell box, 256 x 256, 2
 * threads, against the 16384-spp reference, block / pixel relative RMSE (mean of seeds 1,
 * 2, 3), render seconds: jittered 40 x 40 strata, 1600 rays 0.497 / 0.853 %, 1.62-1.69 s
 * (800 rays 0.795 / 0.984 %; 3200 0.476 / 0.811 %); scrambled Sobol 1024 rays 0.530 /
 * 0.861 %, 1.25-1.37 s; 2048 0.458 / 0.810 %, 1.66-1.78 s; 4096 0.415 / 0.787 %, 2.5-2.8 s
 * (every vertex given them all; with its share by area, below, 2048 at most: 0.472 /
 * 0.817 % with 37 % fewer rays).
 * The mean of three seeds' 1600-ray images reads 0.412 / 0.785 %: what is left at 4096 is
 * the render's bias and the reference's own noise (0.09 / 0.68 %). Earlier, against an
 * older reference: jittered 1024 rays 0.838 / 1.102 %, 1.23 s; 1296 0.826 / 1.062 %, 1.50 s;
 * 1600 0.780 / 1.046 %, 1.62 s; 2025 0.774 / 1.022 %, 1.84 s. */
#define VERTEX_GATHER_RAYS 2048u

/* A vertex's gather takes rays in proportion to the square root of the area around it
 * (its patches' areas summed), up to the next power of two: its noise spreads over that
 * area, so for a given number of rays in all, the image's squared error summed over its
 * pixels is least so. The area given all the rays (VERTEX_GATHER_RAYS, or a correction's
 * gather_rays) is the GATHER_FULL_SHARE quantile of the gathering vertices' areas (a whole
 * patch's vertex, next to the pieces light_refine splits); the fewest, 1/GATHER_FEWEST_PART
 * of all. */
#define GATHER_FULL_SHARE 0.9
#define GATHER_FEWEST_PART 8u

/* A vertex that no pixel shows (the render's camera rays meet none of its patches: the far
 * faces of a box, what lies behind the camera) gathers with 1/VERTEX_UNSHOWN_PART of its
 * rays: its light only lights the second gather's field, whose 128 rays a vertex average
 * over many vertices. */
#define VERTEX_UNSHOWN_PART 8u

/* Per mesh vertex v (mesh->vertex_count values): direct[v], the emitters' direct
 * irradiance, sharp[v] the sharp sources', and gathered[v], the irradiance the view's
 * reflected light brings. direct and sharp may be NULL: not asked for, nor traced. A
 * vertex of hidden patches alone gets 0. Deterministic per seed for any thread and rank
 * count. */
rad_status vertex_light(const vertex_light_job *job, rad_rgb *direct, rad_rgb *sharp,
                        rad_rgb *gathered, rad_error *error);

#endif
