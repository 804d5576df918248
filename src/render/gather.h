/*
 * gather.h - what a final-gather ray meets of a radiosity solution (internal): the light
 * the surfaces reflect, (B - E) / pi interpolated at the hit from the display vertices
 * (emission left out: the gathering point takes the emitters' direct light its own way),
 * the twin's value on the back of a two-sided patch, and the sky where the ray leaves the
 * scene. A view of a change of that light (a correction: vertex_radiance.c) has B NULL and
 * lights NULL: only `reflected` changed, so the twins' backs and the sky meet nothing.
 * Used by the gather at the mesh's vertices (vertex_light.c), which traces its rays in
 * batches with gather_trace: against the scene's triangles and then located in the
 * display mesh (display_locate.h) when the view has a locator, else against the display
 * mesh's `tracer`.
 */
#ifndef RAD_RENDER_GATHER_H
#define RAD_RENDER_GATHER_H

#include "lights/direct_light.h"
#include "radiosity.h"
#include "reconstruct/display_locate.h"

typedef struct gather_view {
    const rad_mesh *mesh;
    const uint32_t (*triangles)[3]; /* the display triangles, into display vertices */
    const uint32_t *patch_of;       /* display triangle -> patch */
    const rad_rgb *reflected;       /* per display vertex: (B - E) / pi */
    const rad_rgb *B;               /* per patch (NULL: the twins' backs meet nothing) */
    const rad_rgb *exitance;        /* per patch: E, as the solve used it */
    const light_set *lights;        /* NULL: no sky */
    const rad_tracer *tracer;       /* the display's front triangles */
    const rad_tracer *scene_tracer; /* the scene's triangles, with */
    const display_locator *locator; /* where their hits lie in the display (NULL: none) */
} gather_view;

/* The hits of `count` rays in coherent runs (a vertex's strata) on the display triangles,
 * as gather_seen takes them: rad_tracer_intersect on `tracer`, or the same found faster
 * through the scene's triangles and the locator (a ray it cannot place is traced on
 * `tracer`). */
void gather_trace(const gather_view *view, const rad_ray *rays, uint32_t count, rad_hit *hits);

/* The radiance the ray meets (0 on the back of a one-sided patch). */
rad_rgb gather_seen(const gather_view *view, const rad_ray *ray, const rad_hit *hit);

#endif
