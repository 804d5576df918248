/*
 * vertex_radiance.h - the radiance at a solution's display vertices from the light
 * computed there (vertex_light.h): what the default render interpolates over its display
 * triangles and what the lit mesh carries, from one function (internal).
 *
 * A vertex shows E / pi + f (H_emitters + H_gathered [+ H_sharp]), with E and f = rho / pi
 * the area-weighted means of its visible patches' exitance and albedo (f = 1 / pi and
 * E = 0 where the vertex holds irradiance: a textured patch in an image, whose hits read
 * the texel, or an irradiance image); then T-vertices and added vertices are made
 * displayable. The render adds the sharp sources (point, spot, luminaire, sun) at each
 * hit; the lit mesh, which has no hits, adds them at the vertex.
 *
 * H_gathered is gathered twice. The first gather meets the solution's patch values,
 * (B - E) / pi interpolated: next to a contact or in a shadow those are means over patches
 * that the contact or the shadow edge cuts, so a point near them gathers a smeared field
 * (the foot of a box's face, which sees mostly the floor at the box's foot, came out 20-30 %
 * dark). The light just computed at the vertices is that field resolved at the points:
 * f_rho (H_emitters + H_sharp + H_gathered), f_rho the vertex's mean rho / pi whatever it
 * shows. A second gather of CORRECTION_RAYS rays meets the change from the first field to
 * that one and adds it: the same as gathering the new field, as the gather is linear, but
 * the change is small almost everywhere, so a quarter of the rays carries it without new
 * noise.
 */
#ifndef RAD_RENDER_VERTEX_RADIANCE_H
#define RAD_RENDER_VERTEX_RADIANCE_H

#include "lights/direct_light.h"
#include "lights/emitters.h"
#include "radiosity.h"
#include "reconstruct/display_mesh.h"
#include "render/gather.h"
#include "render/vertex_light.h"
#include "scene/patch_materials.h"

typedef struct vertex_radiance_job {
    const rad_mesh *mesh;
    const display_mesh *display;
    const rad_scene *scene;
    const rad_patch_inputs *inputs;      /* the patch inputs B was solved with */
    const patch_material_lookup *lookup; /* NULL, or its textured patches hold irradiance */
    bool irradiance;                     /* every vertex holds irradiance */
    const emitter_set *emitters;
    const emitter_shadows *shadows;      /* NULL, or their light exactly (emitter_shadows.h) */
    const rad_tracer *scene_tracer;      /* the scene's triangles */
    const gather_view *view;             /* what the gather rays meet */
    const light_set *sharp;              /* NULL, or the scene's sharp sources */
    bool sharp_at_hits;                  /* H_sharp left out: each hit adds its own (it
                                            still lights the second gather's field) */
    const uint8_t *hidden;               /* patches no one sees */
    const vertex_parents *parents;       /* per vertex, or NULL (vertex_light_job) */
    uint8_t *sees;                       /* out, or NULL: per mesh vertex, what its shadow
                                            rays found (vertex_light_job) */
    rad_rgb *without_emitters;           /* out, or NULL: per display vertex, the radiance
                                            without H_emitters (for the pixels that add
                                            their own) */
    const uint8_t *shown;                /* per mesh vertex, or NULL (all): whether a pixel
                                            may show it; one none shows gathers with
                                            VERTEX_UNSHOWN_PART of the rays, and takes no
                                            second gather (vertex_light_job.shown) */
    bool penumbra_at_pixels;             /* the caller computes the emitters' light at the
                                            pixels of every display triangle with a corner
                                            that sees a part of it (needs `sees`):
                                            vertex_light_job.penumbra_at_pixels */
    double leave;                        /* how far rays start off a surface */
    bool emitters_at_hits;               /* H_emitters left out: each hit adds its own (it
                                            still lights the second gather's field) */
    uint64_t seed;
    int threads;
    bool over_ranks; /* collective over MPI ranks, each lighting its share of the vertices
                        (vertex_light); false: this rank alone lights them all */
} vertex_radiance_job;

/* radiance[v] for the display's vertices; irradiance (NULL, or display->vertex_count
 * values) gets each vertex's incident irradiance H_emitters + H_gathered [+ H_sharp]. */
rad_status vertex_radiance(const vertex_radiance_job *job, rad_rgb *radiance,
                           rad_rgb *irradiance, rad_error *error);

/* What the light at the vertices holds at its peak, per patch of the mesh it is computed
 * on: the per-vertex arrays, the display mesh's tracer and the scene's. Measured with
 * --max-memory's high-water mark (rad_memory_budget_peak) around the lit mesh of `solve`,
 * 2 threads, the light's finer mesh left out: 725 bytes a patch on a furnished room of
 * 29152 patches, 737 on the Cornell box's 3742; rounded up (800), and 64 more for what the
 * render adds since it computes the emitters' light in penumbrae at the pixels (the
 * radiance without it, 24 bytes a display vertex, and a byte a vertex and a triangle: a
 * Cornell box's hierarchical render under --max-memory 8M needed 1.5 MB of it past 800). */
#define VERTEX_LIGHT_BYTES_PER_PATCH 864u

/* Whether the light at the vertices has anything to compute for this scene: emitting
 * surfaces or light sources (else the solution's patch values are all there is). */
bool vertex_radiance_applies(const rad_scene *scene);

/* What gather rays meet: the light the patches reflect, (B - E) / pi, at the display's
 * vertices (patches in `hidden` left out), into reflected[display->vertex_count]. False
 * when out of memory. */
bool vertex_radiance_reflected(const rad_mesh *mesh, const display_mesh *display,
                               const rad_rgb *B, const rad_rgb *exitance,
                               const uint8_t *hidden, rad_rgb *reflected);

/* How far rays start off a surface of this mesh: past the float rounding of hit points at
 * the scene's size and distance from the origin (scene units). */
double vertex_radiance_leave(const rad_mesh *mesh);

/* The same for a solution alone (the lit mesh): builds what rad_render has at hand (the
 * display's tracer, the hidden patches, the reflected light the gather meets, the
 * emitters and the scene's tracer) and adds the sharp sources at the vertices. Every patch
 * shows its mean albedo (no textures). */
rad_status vertex_radiance_of_solution(const rad_mesh *mesh, const display_mesh *display,
                                       const rad_rgb *B, const rad_scene *scene,
                                       const rad_patch_inputs *inputs,
                                       const vertex_parents *parents, uint64_t seed,
                                       int threads, rad_rgb *radiance, rad_rgb *irradiance,
                                       rad_error *error);

#endif
