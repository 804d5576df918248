/*
 * light_refine.h - a finer mesh to show the light on, where the emitters' shadows bend it
 * (internal).
 *
 * The light at the vertices (vertex_light.h) is exact at each vertex and linear between
 * them, so a penumbra's ends (the kink where it meets the umbra or the open light) are
 * cut off across a whole patch: at a box's foot the light reached 4 cm into the umbra and
 * a contact-shadow profile was 6.5 % of the open light off. This splits, for display only,
 * the one-sided patches whose corners disagree on how much of the emitters' light reaches
 * them: some corner sees all of it and another part or none, or some sees none and
 * another part, or the shares seen differ by more than LIGHT_REFINE_SHARE (64 fixed points
 * on the emitters per vertex); then, with the budget left, those whose corners' openness
 * differs (64 cosine rays per vertex, LIGHT_REFINE_OPEN below): next to a crease or a
 * contact the light the surfaces around reflect bends too (the floor in front of a
 * block's foot was 4-34 % too bright over 2-3 pixels at 256 x 256, the ceiling creases
 * 2-3 %, and the ceiling around a lamp hanging just below it darkened). Quads split into
 * four quads at their edges' midpoints and centre, triangles into four; the new corners
 * are tested in turn, `levels` times at most, and the splits stop at a budget of added
 * patches (and of memory). No piece's edge is made shorter than the dense solvers' default
 * patch size halved by the default shadow levels and then LIGHT_REFINE_LEVELS times: a
 * mesh already that fine is left as it is.
 * On the hierarchical solver's 31,210 patches of the Cornell box the split had cost 2.2 s
 * of a 256 x 256 render (4.82 -> 7.04 s) for no gain (0.871 % / 1.077 % -> 0.872 % /
 * 1.112 % block / pixel against a 16384-spp reference). Each piece keeps its patch's
 * radiosity, material and normal (the solution is not changed: only where its light is
 * shown); a midpoint is shared by the two patches of a region on either side of its edge,
 * and where only one of them splits it is a T-vertex, which the display mesh handles.
 * Two-sided patches (and their twins) are left whole. Deterministic: fixed points on the
 * emitters, patches in order.
 * A vertex added inside a patch whose corners' openness agrees takes its gathered light
 * from the patch's corners (light_refined.parents: the reflected light does not bend
 * there, only the emitters'), so only the emitters' light is computed at it: on the
 * Cornell box at 256 x 256 the render 1.55 -> 1.25 s, its error the same (0.780 / 1.046 %
 * -> 0.782 / 1.055 % block / pixel against the 16384-spp reference, one seed; two seeds
 * differ by 0.52 / 0.58 % either way).
 */
#ifndef RAD_RENDER_LIGHT_REFINE_H
#define RAD_RENDER_LIGHT_REFINE_H

#include "radiosity.h"
#include "render/vertex_light.h"

#define LIGHT_REFINE_LEVELS 2    /* splits of a patch at most (a quarter of its edge) */
#define LIGHT_REFINE_SHARE 0.25  /* corners' shares of the light this far apart split */
#define LIGHT_REFINE_PROBES 64u  /* points on the emitters per vertex test, and cosine rays
                                    for its openness */
/* A vertex's openness: the mean over its cosine rays of min(1, t / reach), reach this many
 * times the dense solvers' default patch size. Corners whose openness differs by more than
 * LIGHT_REFINE_OPEN mark a patch at a crease or a contact, where the light reflected from
 * the surfaces around bends (a block's foot on the floor, a room's edges). */
#define LIGHT_REFINE_REACH 2.0
#define LIGHT_REFINE_OPEN 0.1
/* The creases' budget: the patch count over this (the shadows' is the patch count; what
 * they leave goes to the creases too). Cornell box 256 x 256 against a 16384-spp
 * reference (block / pixel relative RMSE) by the creases' budget: none 1.093 % / 1.322 %
 * (7483 patches shown), a quarter 1.069 / 1.326 (8419), a half 0.963 / 1.318 (9355), all
 * 0.966 / 1.337 (11224); before the creases 1.143 / 1.345 (7198). */
#define LIGHT_REFINE_CREASE_PART 2u
/* A patch a bright region's plane crosses, where the interpolated light would miss the
 * kink that region's reflected light makes there by more than this share of the patch's
 * own (reflector_planes.h), is split too, and its new vertices gather their own light;
 * at most the patch count over LIGHT_REFINE_PLANE_PART added for these, a budget of their
 * own, and none for a patch with under a hundredth of the mean irradiance (the gap above
 * a lamp). On the Cornell box at 128 x 128 against the 65536-spp reference (the CLI's
 * mesh, seeds 1 / 2 / 3, block / pixel relative RMSE): 0.399 / 0.403 / 0.443 % and
 * 0.703 / 0.706 / 0.698 % before, 0.406 / 0.396 / 0.440 % and 0.685 / 0.690 / 0.683 %
 * after; the tall block's face at the short block's top +2.3 % -> +0.05 %. At 0.01 the
 * short block's side faces' planes split the tall block's face down to its foot, where the
 * vertices' gather is known to read dark (test_render_accuracy: the foot -2.7 % -> -3.9 %
 * on the library's mesh); at 0.03 it stays at -2.7 %. Taken from the creases' budget the
 * splits left creases unsplit. */
#define LIGHT_REFINE_KINK 0.03
#define LIGHT_REFINE_PLANE_PART 8u
/* What the finer mesh holds per patch besides the light at its vertices
 * (VERTEX_LIGHT_BYTES_PER_PATCH): the piece, its inputs and B, where it comes from, the
 * vertices. Measured (rad_memory_in_use before and after light_refine, 2 threads): 302
 * bytes a patch of the finer mesh on a furnished room (39985 patches from 29152), 301 on
 * the Cornell box (9355 from 3742); rounded up. Before the whole finer mesh and the light
 * after it were counted (an added patch at 4096 bytes against a quarter of what was left),
 * that room's lit mesh under --max-memory 32M to 38M ran the solve and then failed. With
 * where each vertex's gathered light comes from (20 bytes a vertex, about 1.3 vertices a
 * patch) 352. */
#define LIGHT_REFINE_BYTES_PER_PATCH 352u

/* The solution on the finer mesh: mesh (NULL when nothing was split: use the caller's),
 * B and inputs per patch of it, each piece its patch's, and where each piece comes from;
 * destroy with light_refined_free. */
typedef struct light_refined {
    rad_mesh *mesh;
    rad_rgb *B;
    rad_patch_inputs *inputs;
    uint32_t *parent; /* per patch of mesh: the patch of the solution's mesh it lies in */
    vertex_parents *parents; /* per vertex of mesh: where its gathered light comes from */
} light_refined;

/* Refines `mesh` (solution B, patch inputs `inputs`, NULL: built from the scene) for the
 * emitting surfaces of `scene`; adds at most 1.5 x mesh->patch_count patches, and under a
 * memory budget (--max-memory) no more than lets the finer mesh and the light at its
 * vertices fit three quarters of the budget left, at LIGHT_REFINE_BYTES_PER_PATCH +
 * VERTEX_LIGHT_BYTES_PER_PATCH a patch (none when the mesh alone takes that). Nothing to
 * do (no emitter, no split) leaves out->mesh NULL. */
rad_status light_refine(const rad_scene *scene, const rad_mesh *mesh, const rad_rgb *B,
                        const rad_patch_inputs *inputs, int threads, light_refined *out,
                        rad_error *error);

void light_refined_free(light_refined *refined);

#endif
